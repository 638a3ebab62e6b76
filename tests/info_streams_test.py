"""`voxfield info` streams a scene graph's instances instead of holding them as JSON.

A probe once found `info` building the JSON of every instance even for its text output: 2^20
instances took 2.4 GB where `convert` of the same file needed 69 MB. This test writes a .vox
whose scene graph places 2^17 one-voxel instances in one chunk (a 13 MB file; the world itself is
tiny), then measures the peak resident memory of `info`, `info --json` and `convert` on it, each
in a child process of its own. Held as JSON, 2^17 instances cost about 300 MB on top of the parse;
streamed, `info` needs about what `convert` needs. The bound is relative to `convert` in the same
run, so it holds under AddressSanitizer too.

Usage: info_streams_test.py VOXFIELD_BINARY WORK_DIR
"""

import os
import resource
import struct
import subprocess
import sys

INSTANCES = 1 << 17


def chunk(tag: bytes, content: bytes, children: bytes = b"") -> bytes:
    return tag + struct.pack("<II", len(content), len(children)) + content + children


def dict_bytes(pairs) -> bytes:
    out = struct.pack("<I", len(pairs))
    for k, v in pairs:
        out += struct.pack("<I", len(k)) + k.encode() + struct.pack("<I", len(v)) + v.encode()
    return out


def transform(node: int, child: int, layer: int, frame) -> bytes:
    content = struct.pack("<I", node) + dict_bytes([]) + struct.pack("<iiiI", child, -1, layer, 1)
    return chunk(b"nTRN", content + dict_bytes(frame))


def shape(node: int, model: int) -> bytes:
    return chunk(b"nSHP", struct.pack("<I", node) + dict_bytes([]) + struct.pack("<II", 1, model)
                 + dict_bytes([]))


def group(node: int, children) -> bytes:
    return chunk(b"nGRP", struct.pack("<I", node) + dict_bytes([]) + struct.pack("<I", len(children))
                 + b"".join(struct.pack("<I", c) for c in children))


def swarm_file() -> bytes:
    parts = [chunk(b"SIZE", struct.pack("<III", 1, 1, 1)),
             chunk(b"XYZI", struct.pack("<I", 1) + bytes([0, 0, 0, 1])),
             transform(0, 1, -1, []),
             group(1, [2 + 2 * i for i in range(INSTANCES)])]
    for i in range(INSTANCES):
        # Every instance within one 32^3 chunk: the world stays a few voxels, the graph is large.
        t = f"{i % 16} {(i // 16) % 16} {(i // 256) % 16}"
        parts.append(transform(2 + 2 * i, 3 + 2 * i, 0, [("_t", t)]))
        parts.append(shape(3 + 2 * i, 0))
    return b"VOX " + struct.pack("<I", 150) + chunk(b"MAIN", b"", b"".join(parts))


def peak_rss_mib(cmd) -> float:
    """Runs cmd in a fresh Python child so that RUSAGE_CHILDREN holds only its own peak."""
    probe = ("import resource, subprocess, sys\n"
             "r = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)\n"
             "sys.stderr.write(r.stderr.decode(errors='replace'))\n"
             "print(r.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n")
    # Under AddressSanitizer, freed memory waits in a quarantine (256 MB by default) before it is
    # reused, so a process that allocates and frees per instance peaks far above what it holds:
    # without the quarantine the peak is what the program keeps (other builds ignore the option).
    env = dict(os.environ)
    env["ASAN_OPTIONS"] = ":".join(filter(None, [env.get("ASAN_OPTIONS"), "quarantine_size_mb=0"]))
    out = subprocess.run([sys.executable, "-c", probe, *cmd], capture_output=True, text=True,
                         env=env)
    code, kib = out.stdout.split()
    if code != "0":
        raise SystemExit(f"FAIL: {' '.join(cmd)} exited {code}: {out.stderr.strip()[:400]}")
    return int(kib) / 1024.0


def main() -> int:
    voxfield, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, "swarm.vox")
    with open(path, "wb") as f:
        f.write(swarm_file())
    convert = peak_rss_mib([voxfield, "convert", path, os.path.join(work, "swarm.vfw")])
    text = peak_rss_mib([voxfield, "info", path])
    js = peak_rss_mib([voxfield, "info", "--json", path])
    # The instance count must be what info reports, or the file did not say what we meant.
    listed = subprocess.run([voxfield, "info", "--json", path], capture_output=True, text=True)
    count = listed.stdout.count('"model":')
    print(f"peak RSS: convert {convert:.0f} MiB, info {text:.0f} MiB, info --json {js:.0f} MiB; "
          f"{count} instances listed")
    failures = 0
    if count != INSTANCES:
        print(f"FAIL: info --json listed {count} instances, expected {INSTANCES}", file=sys.stderr)
        failures += 1
    bound = 1.25 * convert + 24.0
    for name, rss in (("info", text), ("info --json", js)):
        if rss > bound:
            print(f"FAIL: {name} peaked at {rss:.0f} MiB, over {bound:.0f} MiB (1.25 x convert + 24)",
                  file=sys.stderr)
            failures += 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
