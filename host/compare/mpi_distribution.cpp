// MpiDistribution (see mpi_distribution.hpp): a length then the bytes, so texts of any size.
#include "compare/mpi_distribution.hpp"

#include <mpi.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

namespace tissue::host {
namespace {

void check(int code, const char* what) {
  if (code != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed");
}

// MPI counts are ints: long texts go in pieces.
void broadcast_chunks(char* data, std::size_t size) {
  for (std::size_t at = 0; at < size;) {
    const int piece = static_cast<int>(std::min<std::size_t>(size - at, INT_MAX));
    check(MPI_Bcast(data + at, piece, MPI_CHAR, 0, MPI_COMM_WORLD), "MPI_Bcast");
    at += static_cast<std::size_t>(piece);
  }
}

}  // namespace

bool launched_by_mpi() {
  for (const char* variable : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"}) {
    if (std::getenv(variable) != nullptr) return true;
  }
  return false;
}

MpiDistribution::MpiDistribution(int& argc, char**& argv) {
  int provided = 0;
  check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  if (provided < MPI_THREAD_FUNNELED) {
    MPI_Finalize();
    throw std::runtime_error("MPI: the library does not support threads calling it from the main thread only");
  }
  check(MPI_Comm_rank(MPI_COMM_WORLD, &m_rank), "MPI_Comm_rank");
  check(MPI_Comm_size(MPI_COMM_WORLD, &m_size), "MPI_Comm_size");
}

MpiDistribution::~MpiDistribution() { MPI_Finalize(); }

void MpiDistribution::broadcast(std::string& bytes) {
  std::uint64_t size = bytes.size();
  check(MPI_Bcast(&size, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD), "MPI_Bcast");
  bytes.resize(size);
  broadcast_chunks(bytes.data(), bytes.size());
}

std::vector<std::string> MpiDistribution::gather(const std::string& text) {
  // Rows are short text lines: a gather of the lengths, then each rank's text to rank 0.
  if (text.size() > static_cast<std::size_t>(INT_MAX)) throw std::runtime_error("MPI: rows too long to gather");
  const int length = static_cast<int>(text.size());
  std::vector<int> lengths(m_rank == 0 ? static_cast<std::size_t>(m_size) : 0);
  check(MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD), "MPI_Gather");
  std::vector<int> offsets(lengths.size());
  long long total = 0;
  for (std::size_t r = 0; r < lengths.size(); ++r) {
    offsets[r] = static_cast<int>(total);
    total += lengths[r];
    if (total > INT_MAX) throw std::runtime_error("MPI: rows too long to gather");
  }
  std::string all(static_cast<std::size_t>(total), '\0');
  check(MPI_Gatherv(text.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR, 0,
                    MPI_COMM_WORLD),
        "MPI_Gatherv");
  std::vector<std::string> texts;
  for (std::size_t r = 0; r < lengths.size(); ++r) {
    texts.push_back(all.substr(static_cast<std::size_t>(offsets[r]), static_cast<std::size_t>(lengths[r])));
  }
  return texts;
}

void MpiDistribution::abort_all(int exit_code) {
  MPI_Abort(MPI_COMM_WORLD, exit_code);
  std::exit(exit_code);
}

}  // namespace tissue::host
