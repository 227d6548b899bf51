#pragma once
// edm-bench-soak's records of a phase (the jobs, the /proc samples, the task statistics) and the
// figures and reports made from them. Non-RT; plain values.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "soak_job.hpp"
#include "soak_plc.hpp"

namespace edm::bench::soak {

struct JobRecord {
  int index{0};
  double start_s{0}, wall_s{0};
  int busy_retries{0};
  std::string error;  // edmhmi did not exit 0 / no report
  JobFigures fig;
};

struct TaskStats {
  std::string name;
  std::uint64_t cycles{0}, overruns{0};
  double p99_us{0}, max_us{0};
};

struct Phase {
  std::string name;
  std::vector<JobRecord> jobs;
  std::vector<ProcSample> samples;
  std::optional<std::size_t> ref;  // the first sample after the first job
  ProcSample start_q, end_q;       // quiesced: nobody connected
  std::string crash;               // how edmplc ended if it was not our SIGINT
  double crash_t_s{-1};
  bool answered_at_end{false}, clean_stop{false}, rss_killed{false};
  std::vector<TaskStats> tasks;
  double seconds{0};
};

struct MemFigures {
  long rss_start_kb{0}, rss_ref_kb{0}, rss_end_kb{0}, rss_max_kb{0};
  int fd_start{0}, fd_ref{0}, fd_end{0}, fd_max{0};
};

/// Resident size and descriptors at the quiesced start and end, after job 1, and the maxima.
MemFigures mem_figures(const Phase& ph);
std::size_t jobs_at_depth(const Phase& ph);
std::string mib(long kb);  // KiB as MiB with one decimal
/// The samples as CSV: t_s, rss_kb, fds.
void write_samples(const std::filesystem::path& path, const Phase& ph);
/// --memory: the resident size over a run of the job loop alone. Exit 0 flat, 1 not (or failed).
int memory_report(const Phase& ph, const std::filesystem::path& out);

}  // namespace edm::bench::soak
