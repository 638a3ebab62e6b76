// voxfield MPI tests — the job every test runs in: MPI_COMM_WORLD, this process's rank and the
// number of ranks (mpirun -np N).
#pragma once

#include <mpi.h>

namespace voxfield::test {

inline MPI_Comm comm() {
  return MPI_COMM_WORLD;
}
inline int rank() {
  int r = 0;
  MPI_Comm_rank(comm(), &r);
  return r;
}
inline int ranks() {
  int n = 0;
  MPI_Comm_size(comm(), &n);
  return n;
}

}  // namespace voxfield::test
