// Where the runs of tissue-host compare go: this process alone, or the ranks of an MPI job
// (mpi_distribution.hpp, linked into tissue-host only). Runs are dealt round robin over the ranks;
// rank 0 runs the reference first and sends its trace to every rank, each rank compares its own
// runs with it, and rank 0 gathers the rows (as text) and writes the outputs.
#pragma once

#include <string>
#include <vector>

namespace tissue::host {

class RunDistribution {
 public:
  virtual ~RunDistribution() = default;
  [[nodiscard]] virtual int rank() const = 0;
  [[nodiscard]] virtual int size() const = 0;
  /// Rank 0's `bytes` to every rank (collective: every rank calls it).
  virtual void broadcast(std::string& bytes) = 0;
  /// Every rank's `text`, in rank order, on rank 0; empty on the others (collective).
  [[nodiscard]] virtual std::vector<std::string> gather(const std::string& text) = 0;
};

/// One process: rank 0 of 1.
class SingleProcess final : public RunDistribution {
 public:
  [[nodiscard]] int rank() const override { return 0; }
  [[nodiscard]] int size() const override { return 1; }
  void broadcast(std::string& /*bytes*/) override {}
  [[nodiscard]] std::vector<std::string> gather(const std::string& text) override { return {text}; }
};

}  // namespace tissue::host
