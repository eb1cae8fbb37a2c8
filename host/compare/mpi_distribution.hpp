// RunDistribution over MPI (`mpirun -n N tissue-host compare ...`). Compiled into tissue-host
// only; MPI is initialized only for compare and only when a launcher started the process, so
// `tissue-host run` never touches it.
#pragma once

#include "compare/run_distribution.hpp"

#include <string>
#include <vector>

namespace tissue::host {

/// True when an MPI launcher (mpirun/mpiexec of Open MPI, MPICH or a PMIx launcher) started us.
[[nodiscard]] bool launched_by_mpi();

/// MPI_Init_thread (funneled: only the main thread calls MPI; runs go on worker threads) in the
/// constructor, MPI_Finalize in the destructor. One per process.
class MpiDistribution final : public RunDistribution {
 public:
  MpiDistribution(int& argc, char**& argv);
  ~MpiDistribution() override;
  MpiDistribution(const MpiDistribution&) = delete;
  MpiDistribution& operator=(const MpiDistribution&) = delete;
  MpiDistribution(MpiDistribution&&) = delete;
  MpiDistribution& operator=(MpiDistribution&&) = delete;

  [[nodiscard]] int rank() const override { return m_rank; }
  [[nodiscard]] int size() const override { return m_size; }
  void broadcast(std::string& bytes) override;
  [[nodiscard]] std::vector<std::string> gather(const std::string& text) override;
  /// Ends every rank (after an error on one, so that the others do not wait forever).
  [[noreturn]] static void abort_all(int exit_code);

 private:
  int m_rank = 0, m_size = 1;
};

}  // namespace tissue::host
