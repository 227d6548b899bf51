#include "soak_report.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <fstream>

namespace edm::bench::soak {

MemFigures mem_figures(const Phase& ph) {
  MemFigures m;
  m.rss_start_kb = ph.start_q.rss_kb;
  m.fd_start = ph.start_q.fds;
  m.rss_end_kb = ph.end_q.rss_kb;
  m.fd_end = ph.end_q.fds;
  for (const auto& s : ph.samples) {
    m.rss_max_kb = std::max(m.rss_max_kb, s.rss_kb);
    m.fd_max = std::max(m.fd_max, s.fds);
  }
  if (ph.ref && *ph.ref < ph.samples.size()) {
    m.rss_ref_kb = ph.samples[*ph.ref].rss_kb;
    m.fd_ref = ph.samples[*ph.ref].fds;
  }
  return m;
}

std::size_t jobs_at_depth(const Phase& ph) {
  return static_cast<std::size_t>(std::count_if(
      ph.jobs.begin(), ph.jobs.end(), [](const JobRecord& j) { return j.fig.at_depth(); }));
}

std::string mib(long kb) { return fmt::format("{:.1f}", static_cast<double>(kb) / 1024.0); }

void write_samples(const std::filesystem::path& path, const Phase& ph) {
  std::ofstream csv(path);
  csv << "t_s,rss_kb,fds\n";
  for (const auto& s : ph.samples) {
    csv << fmt::format("{:.1f},{},{}\n", s.t_s, s.rss_kb, s.fds);
  }
}

constexpr long kMemoryFlatKb = 1024;  // --memory: "flat" = end ≤ after job 1 + 1 MiB

int memory_report(const Phase& ph, const std::filesystem::path& out) {
  write_samples(out / "memory-samples.csv", ph);
  const MemFigures m = mem_figures(ph);
  const bool ran = ph.crash.empty() && ph.clean_stop && m.rss_ref_kb > 0;
  // Least-squares slope of VmRSS over the samples from the end of job 1 on, KiB per minute.
  double n = 0, st = 0, sr = 0, stt = 0, str = 0;
  for (std::size_t i = ph.ref.value_or(ph.samples.size()); i < ph.samples.size(); ++i) {
    const double t = ph.samples[i].t_s / 60.0;
    const auto r = static_cast<double>(ph.samples[i].rss_kb);
    n += 1;
    st += t;
    sr += r;
    stt += t * t;
    str += t * r;
  }
  const double den = n * stt - st * st;
  const double slope = n > 1 && den > 0 ? (n * str - st * sr) / den : 0.0;
  fmt::print("\nmemory (VmRSS of edmplc, drill-sim; the job loop alone, {:.0f} s, {} jobs)\n",
             ph.seconds, ph.jobs.size());
  fmt::print("  loaded, idle (bridge up, before job 1)   {:>8} MiB\n", mib(m.rss_start_kb));
  fmt::print("  after job 1                              {:>8} MiB\n", mib(m.rss_ref_kb));
  double next_min = 1;
  for (const auto& smp : ph.samples) {
    if (smp.t_s >= next_min * 60.0) {
      fmt::print("  at {:>4.0f} s                                {:>8} MiB\n", smp.t_s,
                 mib(smp.rss_kb));
      next_min += 1;
    }
  }
  fmt::print("  end (quiesced)                           {:>8} MiB\n", mib(m.rss_end_kb));
  fmt::print("  max                                      {:>8} MiB\n", mib(m.rss_max_kb));
  fmt::print("  slope after job 1                        {:>8.1f} KiB/min\n", slope);
  const bool flat = ran && m.rss_end_kb <= m.rss_ref_kb + kMemoryFlatKb;
  fmt::print("  {} flat: end {} MiB <= after job 1 {} MiB + 1 MiB{}\n", flat ? "PASS" : "FAIL",
             mib(m.rss_end_kb), mib(m.rss_ref_kb),
             ran ? "" : " (edmplc did not run to the end cleanly: " + ph.crash + ")");
  fmt::print("  written: {}/memory-samples.csv (t_s, rss_kb, fds), memory/edmplc.log\n",
             out.string());
  return flat ? 0 : 1;
}

}  // namespace edm::bench::soak
