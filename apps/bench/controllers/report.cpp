// Reports of the controller benchmark: markdown table, CSV, gnuplot plot.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench.hpp"

namespace edm::bench {
namespace {

std::string fixed(double x, int precision) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", precision, x);
  return buf;
}

std::ofstream open_out(const std::string& path) {
  std::ofstream f(path, std::ios::trunc);
  if (!f) {
    throw std::runtime_error(path + ": cannot write");
  }
  return f;
}

}  // namespace

std::string markdown_table(const ScenarioResult& r) {
  const Scenario& s = *r.scenario;
  std::ostringstream md;
  const std::size_t n = r.outcomes.empty() ? 0 : r.outcomes[0].size();
  md << "**" << s.id << "** " << s.title << " (mean ± SD over " << n << " seeds)\n\n";
  md << "| controller |";
  for (const Column& c : s.columns) {
    md << ' ' << c.header << " |";
  }
  md << "\n|---|";
  for (std::size_t i = 0; i < s.columns.size(); ++i) {
    md << "---|";
  }
  md << '\n';
  for (std::size_t v = 0; v < s.variants.size(); ++v) {
    md << "| " << s.variants[v].name << " |";
    for (const Column& c : s.columns) {
      std::vector<double> xs;
      for (const Outcome& o : r.outcomes[v]) {
        xs.push_back(c.get(o));
      }
      if (std::all_of(xs.begin(), xs.end(), [](double x) { return std::isnan(x); })) {
        md << " — |";  // the figure does not apply to this controller
        continue;
      }
      const auto [m, sd] = mean_sd(xs);
      md << ' ' << fixed(m, c.precision) << " ± " << fixed(sd, c.precision) << " |";
    }
    md << '\n';
  }
  return md.str();
}

void write_csv(const std::string& dir, const ScenarioResult& r,
               const std::vector<std::uint64_t>& seeds) {
  const Scenario& s = *r.scenario;
  auto f = open_out(dir + "/" + s.id + ".csv");
  f << "scenario,controller,seed";
  for (const auto& [name, value] : Outcome{}.fields()) {
    f << ',' << name;
  }
  f << '\n';
  for (std::size_t v = 0; v < s.variants.size(); ++v) {
    for (std::size_t i = 0; i < r.outcomes[v].size(); ++i) {
      f << s.id << ",\"" << s.variants[v].name << "\"," << seeds[i];
      for (const auto& [name, value] : r.outcomes[v][i].fields()) {
        f << ',' << fixed(value, 6);
      }
      f << '\n';
    }
  }
}

std::string write_plot(const std::string& dir, const ScenarioResult& r) {
  const Scenario& s = *r.scenario;
  const Column& c = s.columns.at(s.plot_column);
  {
    auto dat = open_out(dir + "/" + s.id + ".dat");
    dat << "# index mean sd controller\n";
    for (std::size_t v = 0; v < s.variants.size(); ++v) {
      std::vector<double> xs;
      for (const Outcome& o : r.outcomes[v]) {
        xs.push_back(c.get(o));
      }
      const auto [m, sd] = mean_sd(xs);
      dat << v << ' ' << m << ' ' << sd << " \"" << s.variants[v].name << "\"\n";
    }
  }
  if (s.plot_jitter) {
    auto dat = open_out(dir + "/" + s.id + "-jitter.dat");
    dat << "# cycle, then mean z-jitter µm over seeds per controller\n";
    std::size_t cycles = 0;
    for (const auto& runs : r.outcomes) {
      for (const Outcome& o : runs) {
        cycles = cycles == 0 ? o.jitter_per_cycle_um.size()
                             : std::min(cycles, o.jitter_per_cycle_um.size());
      }
    }
    for (std::size_t k = 0; k < cycles; ++k) {
      dat << k;
      for (const auto& runs : r.outcomes) {
        std::vector<double> xs;
        for (const Outcome& o : runs) {
          xs.push_back(o.jitter_per_cycle_um[k]);
        }
        dat << ' ' << mean_sd(xs).first;
      }
      dat << '\n';
    }
  }
  // The first seed's run per controller, Rab against time (seed 000's Figs. 9-12); a broken
  // wire's line ends at the break.
  double rab_ref = 0.0;
  if (s.plot_rab) {
    auto dat = open_out(dir + "/" + s.id + "-rab.dat");
    dat << "# t s, then Rab (1 s mean) of the first seed per controller; NaN after a break\n";
    std::size_t secs = 0;
    for (const auto& runs : r.outcomes) {
      if (!runs.empty()) {
        secs = std::max(secs, runs.front().rab_per_s.size());
      }
    }
    for (std::size_t k = 0; k < secs; ++k) {
      dat << k + 1;
      for (const auto& runs : r.outcomes) {
        const bool have = !runs.empty() && k < runs.front().rab_per_s.size();
        dat << ' ' << (have ? runs.front().rab_per_s[k] : std::nan(""));
      }
      dat << '\n';
    }
    rab_ref = s.variants.empty() ? 0.0 : s.variants.front().spec.rab_ref;
  }
  const bool two = s.plot_jitter || s.plot_rab;
  {
    auto gp = open_out(dir + "/" + s.id + ".gp");
    gp << "set terminal pngcairo size 1100," << (two ? 900 : 480) << " noenhanced\nset output '"
       << s.id << ".png'\nset rmargin 18\n";
    if (two) {
      gp << "set multiplot layout 2,1\n";
    }
    gp << "set title \"" << s.id << ": " << s.title << "\"\nset ylabel \"" << c.header
       << " (mean ± SD)\"\nset style fill solid 0.5\nset boxwidth 0.6\n"
       << "set xtics rotate by -15\nplot '" << s.id
       << ".dat' using 1:2:xtic(4) with boxes notitle, '' using 1:2:3 with yerrorbars lc "
          "rgb 'black' pt 0 notitle\n";
    if (s.plot_jitter) {
      gp << "set title \"z-jitter RMS per jump cycle (mean over seeds)\"\nset xlabel \"cycle\"\n"
         << "set ylabel \"µm\"\nset xtics norotate\nset style data linespoints\nplot ";
      for (std::size_t v = 0; v < s.variants.size(); ++v) {
        gp << (v ? ", " : "") << "'" << s.id << "-jitter.dat' using 1:" << v + 2 << " title \""
           << s.variants[v].name << "\"";
      }
      gp << "\nunset multiplot\n";
    }
    if (s.plot_rab) {
      gp << "set title \"Rab, 1 s means, first seed (set point " << rab_ref
         << " dashed)\"\nset xlabel \"t s\"\nset ylabel \"Rab\"\nset xtics norotate\n"
         << "set yrange [0:1]\nset style data lines\nplot " << rab_ref
         << " dt 2 lc rgb 'black' notitle";
      for (std::size_t v = 0; v < s.variants.size(); ++v) {
        gp << ", '" << s.id << "-rab.dat' using 1:" << v + 2 << " title \"" << s.variants[v].name
           << "\"";
      }
      gp << "\nunset multiplot\n";
    }
  }
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) {
    return dir + "/" + s.id + ".gp written; gnuplot not found, no PNG";
  }
  const std::string cmd = "cd '" + dir + "' && gnuplot " + s.id + ".gp 2>/dev/null";
  if (std::system(cmd.c_str()) != 0) {
    return dir + "/" + s.id + ".gp written; gnuplot failed";
  }
  return dir + "/" + s.id + ".png";
}

}  // namespace edm::bench
