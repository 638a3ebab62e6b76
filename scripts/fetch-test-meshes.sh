#!/usr/bin/env bash
# Fetches the classic meshes the mesh-input tests compare against OpenVDB, from Debian's own
# packages — never copied into this repository. The packages are downloaded (apt-get download:
# no installation, no dependencies) and only the meshes are unpacked:
#   glmark2-data   the Stanford bunny (OBJ, 69,666 triangles, closed)
#   libcgal-demo   CGAL's demo data: cow.off (5,804, closed), mech-holes-shark.off (10,192, four
#                  holes), sphere.ply (ASCII, 320), sphere.stl (binary, 320)
#   netgen-doc     netgen's hinge.stl (ASCII STL, 1,212, closed, genus 5)
# Usage: fetch-test-meshes.sh [DIR]   (default /var/cache/voxfield/test-meshes; quick when present)
set -euo pipefail
dir=${1:-${VOXFIELD_TEST_MESHES:-/var/cache/voxfield/test-meshes}}
want=(bunny.obj cow.off mech-holes-shark.off sphere.ply sphere.stl hinge.stl)
have=1
for f in "${want[@]}"; do [ -s "$dir/$f" ] || have=0; done
[ "$have" = 1 ] && exit 0
echo "voxfield: fetching the test meshes (Debian packages glmark2-data, libcgal-demo, netgen-doc) into $dir" >&2
mkdir -p "$dir"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
apt-get download glmark2-data libcgal-demo netgen-doc >/dev/null 2>&1 || {
  apt-get update -qq && apt-get download glmark2-data libcgal-demo netgen-doc >/dev/null; }
dpkg-deb --fsys-tarfile glmark2-data_*.deb | tar -xO ./usr/share/glmark2/models/bunny.obj > bunny.obj
dpkg-deb --fsys-tarfile libcgal-demo_*.deb | tar -xO ./usr/share/doc/libcgal-dev/data.tar.gz |
  tar -xz --strip-components=2 data/meshes/cow.off data/meshes/mech-holes-shark.off \
    data/meshes/sphere.ply data/meshes/sphere.stl
dpkg-deb --fsys-tarfile netgen-doc_*.deb | tar -xO ./usr/share/doc/netgen/examples/hinge.stl > hinge.stl
for f in "${want[@]}"; do [ -s "$f" ] || { echo "voxfield: $f was not in its package" >&2; exit 1; }; done
mv "${want[@]}" "$dir/"
