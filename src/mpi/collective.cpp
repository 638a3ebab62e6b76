// voxfield — agreement between the ranks of a collective operation (collective.h).
#include "collective.h"

namespace voxfield::mpi {

void agree(MPI_Comm comm, const std::string& error, ExchangeStats* stats) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  // The lowest failing rank, or `size` when none failed.
  const int mine = error.empty() ? size : rank;
  int first = size;
  {
    detail::CollectiveTimer t(stats);
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  }
  if (first == size) return;
  // Its message, to every rank. An empty what() still says something.
  std::string text = rank == first ? (error.empty() ? std::string("failed") : error) : "";
  int length = static_cast<int>(text.size());
  MPI_Bcast(&length, 1, MPI_INT, first, comm);
  text.resize(static_cast<std::size_t>(length));
  MPI_Bcast(text.data(), length, MPI_CHAR, first, comm);
  throw RankError(first, text);
}

namespace detail {

std::string mpi_error_text(int code) {
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  if (MPI_Error_string(code, text, &length) != MPI_SUCCESS)
    return "MPI error " + std::to_string(code);
  return std::string(text, static_cast<std::size_t>(length));
}

}  // namespace detail
}  // namespace voxfield::mpi
