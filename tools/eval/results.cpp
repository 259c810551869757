#include "tools/eval/results.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "tools/eval/coverage_plot.hpp"
#include "tools/eval/json.hpp"

namespace storey::tools::eval {

namespace {

// tools/sim fill_from_truth: a floor counts as explored at 90 % ground-truth coverage.
constexpr double kFloorDone = 0.9;

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

std::vector<const MetricsRecord*> finished_metrics(const RunGroup& g) {
  std::vector<const MetricsRecord*> v;
  for (const RunOutcome* r : g.runs)
    if (r->status == RunStatus::finished) v.push_back(&r->metrics);
  return v;
}

template <typename F>
Stat stat_over(const RunGroup& g, F value) {
  std::vector<double> v;
  for (const MetricsRecord* m : finished_metrics(g)) {
    const double x = value(*m);
    if (std::isfinite(x)) v.push_back(x);
  }
  return stat_of(v);
}

const double kNaN = std::nan("");

double floor_coverage(const MetricsRecord& m, size_t f) {
  return f < m.per_floor.size() ? 100.0 * m.per_floor[f].traversable_coverage : kNaN;
}

// "n/a (k of N failed)" / "n/a (not run)" for a group with nothing finished.
std::string missing_text(const RunGroup& g) {
  if (g.failed())
    return "n/a (" + std::to_string(g.failed()) + " of " + std::to_string(g.runs.size()) +
           " failed)";
  return "n/a (not run)";
}

std::string cell(const RunGroup& g, const Stat& s, int decimals, const std::string& none = "n/a") {
  if (g.finished() == 0) return missing_text(g);
  return format_stat(s, decimals, none);
}

std::string runs_text(const RunGroup& g) {
  std::string s = std::to_string(g.finished()) + "/" + std::to_string(g.runs.size());
  std::vector<std::string> notes;
  if (g.failed()) notes.push_back(std::to_string(g.failed()) + " failed");
  if (g.not_run()) notes.push_back(std::to_string(g.not_run()) + " not run");
  for (size_t i = 0; i < notes.size(); ++i) s += (i ? ", " : " (") + notes[i];
  return notes.empty() ? s : s + ")";
}

bool all_floors(const MetricsRecord& m) {
  return m.floors_total > 0 && m.floors_explored >= m.floors_total;
}

std::string success_text(const RunGroup& g) {
  const auto ms = finished_metrics(g);
  if (ms.empty()) return "n/a";
  const size_t k =
      size_t(std::count_if(ms.begin(), ms.end(), [](auto* m) { return all_floors(*m); }));
  if (k == ms.size()) return "Yes";
  if (k == 0) return "No";
  return std::to_string(k) + "/" + std::to_string(ms.size());
}

// Floors that reached 90 %, "1+2"; the most common set over seeds, "(k/n)" when not unanimous.
std::string floors_text(const RunGroup& g) {
  const auto ms = finished_metrics(g);
  if (ms.empty()) return "n/a";
  std::map<std::string, size_t> count;
  std::vector<std::string> order;
  for (const MetricsRecord* m : ms) {
    std::string s;
    for (size_t f = 0; f < m->per_floor.size(); ++f)
      if (m->per_floor[f].traversable_coverage >= kFloorDone) {
        if (!s.empty()) s += '+';  // piecewise: GCC 12 warns (-Wrestrict, false positive)
        s += std::to_string(f + 1);
      }
    if (s.empty()) s = "none";
    if (!count[s]++) order.push_back(s);
  }
  std::string best = order.front();
  for (const auto& s : order)
    if (count[s] > count[best]) best = s;
  if (count[best] == ms.size()) return best;
  return best + " (" + std::to_string(count[best]) + "/" + std::to_string(ms.size()) + ")";
}

// How the finished seeds ended: "done 3, limit 2" (exploration complete / time limit / other),
// so a time column at the time limit is not read as a completion time.
std::string end_text(const RunGroup& g) {
  size_t done = 0, limit = 0, other = 0;
  for (const RunOutcome* r : g.runs) {
    if (r->status != RunStatus::finished) continue;
    if (r->reason.rfind("exploration complete", 0) == 0)
      ++done;
    else if (r->reason.rfind("time limit", 0) == 0)
      ++limit;
    else
      ++other;
  }
  std::string s;
  auto add = [&](size_t n, const char* what) {
    if (n) s += (s.empty() ? "" : ", ") + std::string(what) + " " + std::to_string(n);
  };
  add(done, "done");
  add(limit, "limit");
  add(other, "other");
  return s.empty() ? "n/a" : s;
}

// "Time limits: 1800 s; teaching_building/storey 3000 s." from each finished run's --time-limit:
// the most common value first, then the scene/variant rows whose runs had another (several:
// "1800/3000 s"). "" when no run recorded one.
std::string time_limits_text(const std::vector<RunOutcome>& outcomes) {
  std::map<double, size_t> count;
  std::vector<std::string> rows;                      // scene/variant, in first-seen order
  std::map<std::string, std::vector<double>> limits;  // per row, sorted, distinct
  for (const RunOutcome& r : outcomes) {
    if (r.status != RunStatus::finished || !std::isfinite(r.time_limit_s)) continue;
    ++count[r.time_limit_s];
    const std::string row = r.spec.scene_name() + "/" + r.spec.variant();
    auto [it, fresh] = limits.try_emplace(row);
    if (fresh) rows.push_back(row);
    auto& v = it->second;
    if (std::find(v.begin(), v.end(), r.time_limit_s) == v.end()) {
      v.push_back(r.time_limit_s);
      std::sort(v.begin(), v.end());
    }
  }
  if (count.empty()) return "";
  double common = count.begin()->first;
  for (const auto& [t, n] : count)
    if (n > count[common]) common = t;
  std::string s = "Time limits (each run's --time-limit): " + fmt("%g", common) + " s";
  for (const auto& row : rows) {
    const auto& v = limits[row];
    if (v.size() == 1 && v[0] == common) continue;
    s += "; " + row + " ";
    for (size_t i = 0; i < v.size(); ++i) {
      if (i) s += '/';
      s += fmt("%g", v[i]);
    }
    s += " s";
  }
  return s + ".";
}

std::string safety_text(const RunGroup& g) {
  const auto ms = finished_metrics(g);
  if (ms.empty()) return "n/a";
  double c = 0, f = 0;
  for (const MetricsRecord* m : ms) {
    c += m->collisions;
    f += m->falls;
  }
  return fmt("%.0f", c) + " / " + fmt("%.0f", f);
}

// Paper's row labels for Tables III and IV.
std::string ablation_label(const std::string& a) {
  static const std::map<std::string, std::string> labels = {
      {"", "Full"},
      {"no-tentative", "w/o tentative"},
      {"no-c-sur", "w/o surface crit."},
      {"no-c-exp", "w/o expansion crit."},
      {"boundary-frontiers", "Boundary frontier"},
      {"no-prior", "w/o prior"},
      {"no-incremental", "w/o incr. maint."}};
  const auto it = labels.find(a);
  const std::string name = a.empty() ? "full" : a;
  return (it == labels.end() ? a : it->second) + " (`" + name + "`)";
}

bool in_list(const std::vector<std::string>& list, const std::string& a) {
  return std::find(list.begin(), list.end(), a.empty() ? "full" : a) != list.end();
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string r = "\"";
  for (const char c : s) r += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return r + "\"";
}

std::string stat_json(const Stat& s) {
  if (s.n == 0) return "{\"n\": 0, \"mean\": null, \"std\": null}";
  return "{\"n\": " + std::to_string(s.n) + ", \"mean\": " + json_number(s.mean) +
         ", \"std\": " + json_number(s.std) + "}";
}

size_t max_floors(const std::vector<RunOutcome>& outcomes) {
  size_t n = 0;
  for (const auto& o : outcomes)
    if (o.status == RunStatus::finished) n = std::max(n, o.metrics.per_floor.size());
  return n;
}

}  // namespace

Stat stat_of(const std::vector<double>& v) {
  Stat s;
  s.n = v.size();
  if (v.empty()) return s;
  double sum = 0;
  for (const double x : v) sum += x;
  s.mean = sum / double(v.size());
  if (v.size() > 1) {
    double sq = 0;
    for (const double x : v) sq += (x - s.mean) * (x - s.mean);
    s.std = std::sqrt(sq / double(v.size() - 1));
  }
  return s;
}

size_t RunGroup::finished() const {
  return size_t(std::count_if(runs.begin(), runs.end(),
                              [](auto* r) { return r->status == RunStatus::finished; }));
}
size_t RunGroup::failed() const {
  return size_t(std::count_if(runs.begin(), runs.end(),
                              [](auto* r) { return r->status == RunStatus::failed; }));
}
size_t RunGroup::not_run() const {
  return size_t(std::count_if(runs.begin(), runs.end(),
                              [](auto* r) { return r->status == RunStatus::not_run; }));
}

std::vector<RunGroup> group_runs(const std::vector<RunOutcome>& outcomes) {
  std::vector<RunGroup> groups;
  for (const auto& o : outcomes) {
    const std::string scene = o.spec.scene_name();
    auto it = std::find_if(groups.begin(), groups.end(), [&](const RunGroup& g) {
      return g.scene == scene && g.method == o.spec.method && g.ablation == o.spec.ablation;
    });
    if (it == groups.end()) {
      groups.push_back({scene, o.spec.method, o.spec.ablation, {}});
      it = groups.end() - 1;
    }
    it->runs.push_back(&o);
  }
  return groups;
}

double floor_time(const MetricsRecord& m, size_t f) {
  if (f >= m.per_floor.size() || m.per_floor[f].time_s < 0) return -1.0;
  // The robot's time on the floor until it was explored (tracking.csv): transitions and visits
  // to other floors excluded, as in the paper's Table II.
  if (!std::isnan(m.per_floor[f].time_on_floor_s)) return m.per_floor[f].time_on_floor_s;
  // Records without tracking.csv (before session 32): from the previous floor's 90 %.
  if (f == 0) return m.per_floor[0].time_s;
  const double prev = m.per_floor[f - 1].time_s;
  if (prev < 0 || m.per_floor[f].time_s < prev) return -1.0;
  return m.per_floor[f].time_s - prev;
}

std::string format_stat(const Stat& s, int decimals, const std::string& empty) {
  if (s.n == 0) return empty;
  char b[96];
  std::snprintf(b, sizeof b, "%.*f ± %.*f", decimals, s.mean, decimals, s.std);
  return b;
}

std::string results_markdown(const ResultsInput& in) {
  const auto groups = group_runs(in.outcomes);
  std::ostringstream md;
  size_t fin = 0, fail = 0, nrun = 0;
  for (const auto& o : in.outcomes) {
    fin += o.status == RunStatus::finished;
    fail += o.status == RunStatus::failed;
    nrun += o.status == RunStatus::not_run;
  }
  md << "# storey-eval results\n\n";
  if (!in.command.empty()) md << "Command: `" << in.command << "`\n\n";
  md << in.outcomes.size() << " runs: " << fin << " finished, " << fail << " failed, " << nrun
     << " not run. Cells are mean ± sample standard deviation over the finished seeds; a run "
        "that left no complete metrics.json (or whose record says \"run failed\") is failed and "
        "left out of the means. A floor counts as explored at 90 % ground-truth traversable "
        "coverage.\n\n";
  // Which code the finished runs came from (metrics.json's commit): a resumed matrix can mix.
  std::map<std::string, int> commits;
  for (const auto& o : in.outcomes)
    if (o.status == RunStatus::finished)
      ++commits[o.metrics.commit.empty() ? "not recorded" : o.metrics.commit];
  if (!commits.empty()) {
    md << "Built from commit" << (commits.size() > 1 ? "s " : " ");
    bool first = true;
    for (const auto& [c, n] : commits) {
      md << (first ? "" : ", ") << "`" << c << "` (" << n << " run" << (n == 1 ? "" : "s") << ")";
      first = false;
    }
    md << (commits.size() > 1 ? ": **runs from different code are mixed**" : "") << ".\n\n";
  }

  auto time_of = [](const MetricsRecord& m) { return m.exploration_time_s; };
  auto dist_of = [](const MetricsRecord& m) { return m.trajectory_length_m; };
  auto trav_of = [](const MetricsRecord& m) { return m.traversable_volume_m3; };
  auto occ_of = [](const MetricsRecord& m) { return m.occupied_volume_m3; };
  auto cov_of = [](const MetricsRecord& m) { return 100.0 * m.traversable_coverage; };

  // Table I: every scene x method without ablation.
  md << "## Table I: results in the multi-floor scenes\n\n"
        "| Scene | Method | Runs | Succ. | Floors | End | Exp. time (s) | Traj. dist. (m) | "
        "Trav. vol. (m³) | Occ. vol. (m³) | Coverage (%) | Coll. / falls |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::vector<std::string> truth_notes;
  for (const auto& g : groups) {
    if (!g.ablation.empty()) continue;
    md << "| " << g.scene << " | " << g.method << " | " << runs_text(g) << " | " << success_text(g)
       << " | " << floors_text(g) << " | " << end_text(g) << " | "
       << cell(g, stat_over(g, time_of), 0) << " | " << cell(g, stat_over(g, dist_of), 0) << " | "
       << cell(g, stat_over(g, trav_of), 0) << " | " << cell(g, stat_over(g, occ_of), 0) << " | "
       << cell(g, stat_over(g, cov_of), 1) << " | " << safety_text(g) << " |\n";
  }
  for (const auto& g : groups) {
    const auto ms = finished_metrics(g);
    if (ms.empty()) continue;
    std::string note = g.scene + ": " + fmt("%.0f", ms.front()->gt_traversable_volume_m3) +
                       " m³ traversable, " + fmt("%.0f", ms.front()->gt_occupied_volume_m3) +
                       " m³ occupied, " + std::to_string(ms.front()->floors_total) + " floor(s)";
    if (std::find(truth_notes.begin(), truth_notes.end(), note) == truth_notes.end())
      truth_notes.push_back(note);
  }
  md << "\nSucc.: every floor explored in the seed (paper: \"explores all floors\"); Yes / No / "
        "seeds that did. Floors: the floors explored (1 = lowest), the most common set over the "
        "seeds. End: how the finished seeds ended (done: exploration complete; limit: --time-limit "
        "reached, the time column is then the limit).";
  if (!truth_notes.empty()) {
    md << " Ground truth:";
    for (size_t i = 0; i < truth_notes.size(); ++i) md << (i ? ";" : "") << " " << truth_notes[i];
    md << ".";
  }
  if (const std::string t = time_limits_text(in.outcomes); !t.empty()) md << " " << t;
  md << "\n\n";

  // Table II: per-floor statistics of the proposed method.
  bool any2 = false;
  std::ostringstream t2;
  t2 << "## Table II: per-floor statistics of storey\n\n"
        "| Scene | Runs | 1st floor (s) | 2nd floor (s) | Reduction | 1st-floor cov. (%) | "
        "2nd-floor cov. (%) |\n|---|---|---|---|---|---|---|\n";
  for (const auto& g : groups) {
    if (g.method != "storey" || !g.ablation.empty()) continue;
    any2 = true;
    const Stat f1 = stat_over(g, [](auto& m) {
      const double t = floor_time(m, 0);
      return t >= 0 ? t : kNaN;
    });
    const Stat f2 = stat_over(g, [](auto& m) {
      const double t = floor_time(m, 1);
      return t >= 0 ? t : kNaN;
    });
    std::string red = "n/a";
    if (f1.n && f2.n && f1.mean > 0) red = fmt("%.1f %%", 100.0 * (1.0 - f2.mean / f1.mean));
    t2 << "| " << g.scene << " | " << runs_text(g) << " | " << cell(g, f1, 1, "n/a (not reached)")
       << " | " << cell(g, f2, 1, "n/a (not reached)") << " | " << (g.finished() ? red : "n/a")
       << " | " << cell(g, stat_over(g, [](auto& m) { return floor_coverage(m, 0); }), 1) << " | "
       << cell(g, stat_over(g, [](auto& m) { return floor_coverage(m, 1); }), 1) << " |\n";
  }
  if (any2)
    md << t2.str()
       << "\n1st / 2nd floor: the time the robot stood on the floor (foot within 0.3 m of its "
          "height, tracking.csv) until the floor reached 90 % coverage: stair or ramp "
          "transitions and visits to the other floor excluded, as in the paper. (A record "
          "without tracking.csv: time to 90 % on the 1st floor, from then to 90 % on the 2nd.) "
          "Reduction: 1 - 2nd / 1st (means). The paper's per-floor volumes "
          "are not in metrics.json; per-floor coverage stands in for them. Seeds where a floor "
          "never reached 90 % are left out of that column.\n\n";

  // Tables III and IV: the ablation groups, per scene x method that has any ablated run.
  struct AblationTable {
    const char* title;
    const std::vector<std::string>* members;
    size_t floor;
    const char* floor_name;
  };
  const AblationTable tables[] = {
      {"Table III: ablation on reachable graph and frontier detection", &ablations_group_a(), 0,
       "1st"},
      {"Table IV: ablation on the cross-floor structural prior", &ablations_group_b(), 1, "2nd"}};
  for (const auto& t : tables) {
    std::vector<std::pair<std::string, std::string>> targets;  // (scene, method)
    for (const auto& g : groups)
      if (!g.ablation.empty() && in_list(*t.members, g.ablation) &&
          std::find(targets.begin(), targets.end(), std::pair(g.scene, g.method)) == targets.end())
        targets.emplace_back(g.scene, g.method);
    for (const auto& [scene, method] : targets) {
      md << "## " << t.title << " (" << scene << ", " << method << ")\n\n"
         << "| Configuration | Runs | End | Exp. time (s) | Traj. dist. (m) | Occ. vol. (m³) | "
         << t.floor_name << "-floor time (s) | " << t.floor_name << "-floor cov. (%) |\n"
         << "|---|---|---|---|---|---|---|---|\n";
      for (const auto& name : *t.members) {
        const std::string ab = name == "full" ? "" : name;
        for (const auto& g : groups) {
          if (g.scene != scene || g.method != method || g.ablation != ab) continue;
          const size_t f = t.floor;
          md << "| " << ablation_label(ab) << " | " << runs_text(g) << " | " << end_text(g) << " | "
             << cell(g, stat_over(g, time_of), 0) << " | " << cell(g, stat_over(g, dist_of), 0)
             << " | " << cell(g, stat_over(g, occ_of), 0) << " | "
             << cell(g,
                     stat_over(g,
                               [f](auto& m) {
                                 const double x = floor_time(m, f);
                                 return x >= 0 ? x : kNaN;
                               }),
                     1, "n/a (not reached)")
             << " | " << cell(g, stat_over(g, [f](auto& m) { return floor_coverage(m, f); }), 1)
             << " |\n";
        }
      }
      md << "\nWhole runs of the scene (the paper measures Group A on the first floor and Group "
            "B on the second): time, distance and volume are the whole run's; the floor columns "
            "isolate the floor the paper measured (same definitions as Table II).\n\n";
    }
  }

  // Any other ablation: the Table I columns.
  bool other = false;
  for (const auto& g : groups) {
    if (g.ablation.empty() || in_list(ablations_group_a(), g.ablation) ||
        in_list(ablations_group_b(), g.ablation))
      continue;
    if (!other)
      md << "## Other configurations\n\n| Scene | Variant | Runs | Succ. | Floors | Exp. time (s) "
            "| Traj. dist. (m) | Trav. vol. (m³) | Occ. vol. (m³) | Coverage (%) |\n"
            "|---|---|---|---|---|---|---|---|---|---|\n";
    other = true;
    md << "| " << g.scene << " | " << g.variant() << " | " << runs_text(g) << " | "
       << success_text(g) << " | " << floors_text(g) << " | " << cell(g, stat_over(g, time_of), 0)
       << " | " << cell(g, stat_over(g, dist_of), 0) << " | " << cell(g, stat_over(g, trav_of), 0)
       << " | " << cell(g, stat_over(g, occ_of), 0) << " | " << cell(g, stat_over(g, cov_of), 1)
       << " |\n";
  }
  if (other) md << "\n";

  if (!in.plots.empty()) {
    md << "## Coverage over time\n\nMean over the finished seeds of each method (legend: "
          "seeds averaged); a run keeps its final coverage after it ends.\n\n";
    for (const auto& [scene, file] : in.plots) md << "![" << scene << "](" << file << ")\n\n";
  }

  // Failed runs, grouped by reason.
  std::vector<std::tuple<std::string, std::string, std::string, size_t, size_t>> fails;
  for (const auto& g : groups)
    for (const RunOutcome* r : g.runs) {
      if (r->status != RunStatus::failed) continue;
      auto it = std::find_if(fails.begin(), fails.end(), [&](auto& f) {
        return std::get<0>(f) == g.scene && std::get<1>(f) == g.variant() &&
               std::get<2>(f) == r->reason;
      });
      if (it == fails.end())
        fails.emplace_back(g.scene, g.variant(), r->reason, 1, g.runs.size());
      else
        ++std::get<3>(*it);
    }
  if (!fails.empty()) {
    md << "## Failed runs\n\n| Scene | Variant | Failed | Reason |\n|---|---|---|---|\n";
    for (const auto& [scene, variant, reason, k, n] : fails) {
      std::string r = reason;
      std::replace(r.begin(), r.end(), '|', '/');
      md << "| " << scene << " | " << variant << " | " << k << " of " << n << " | " << r << " |\n";
    }
    md << "\nEach run's output is in runs/<scene>/<variant>/seed<N>/log.txt. Failed runs are "
          "tried again by the next storey-eval with the same --out.\n\n";
  }
  return md.str();
}

std::string results_csv(const std::vector<RunOutcome>& outcomes) {
  const size_t nf = max_floors(outcomes);
  std::ostringstream c;
  c << "scene,method,ablation,seed,status,resumed,exit_code,wall_s,success,floors_total,"
       "floors_explored,exploration_time_s,trajectory_length_m,traversable_coverage,"
       "traversable_volume_m3,occupied_volume_m3,gt_traversable_volume_m3,gt_occupied_volume_m3";
  for (size_t f = 1; f <= nf; ++f) c << ",floor" << f << "_time_s,floor" << f << "_coverage";
  c << ",collisions,falls,safety_stops,walking_time_s,reason,run_dir\n";
  for (const auto& o : outcomes) {
    const bool ok = o.status == RunStatus::finished;
    const MetricsRecord& m = o.metrics;
    auto num = [&](double v, const char* f) { return ok ? fmt(f, v) : std::string(); };
    c << csv_field(o.spec.scene_name()) << "," << csv_field(o.spec.method) << ","
      << csv_field(o.spec.ablation.empty() ? "full" : o.spec.ablation) << "," << o.spec.seed << ","
      << to_string(o.status) << "," << (o.resumed ? 1 : 0) << ","
      << (o.exit_code >= 0 ? std::to_string(o.exit_code) : std::string()) << ","
      << fmt("%.1f", o.wall_s) << "," << (ok ? (m.success ? "1" : "0") : "") << ","
      << num(m.floors_total, "%.0f") << "," << num(m.floors_explored, "%.0f") << ","
      << num(m.exploration_time_s, "%.3f") << "," << num(m.trajectory_length_m, "%.3f") << ","
      << num(m.traversable_coverage, "%.4f") << "," << num(m.traversable_volume_m3, "%.3f") << ","
      << num(m.occupied_volume_m3, "%.3f") << "," << num(m.gt_traversable_volume_m3, "%.3f") << ","
      << num(m.gt_occupied_volume_m3, "%.3f");
    for (size_t f = 0; f < nf; ++f) {
      const bool has = ok && f < m.per_floor.size();
      c << "," << (has ? fmt("%.3f", m.per_floor[f].time_s) : "") << ","
        << (has ? fmt("%.4f", m.per_floor[f].traversable_coverage) : "");
    }
    c << "," << num(m.collisions, "%.0f") << "," << num(m.falls, "%.0f") << ","
      << num(m.safety_stops, "%.0f") << ","
      << (ok && std::isfinite(m.walking_time_s) ? fmt("%.3f", m.walking_time_s) : "") << ","
      << csv_field(o.reason) << "," << csv_field(o.spec.rel_dir()) << "\n";
  }
  return c.str();
}

std::string results_json(const ResultsInput& in) {
  std::ostringstream j;
  j << "{\n  \"command\": " << json_quote(in.command) << ",\n  \"runs\": [";
  for (size_t i = 0; i < in.outcomes.size(); ++i) {
    const RunOutcome& o = in.outcomes[i];
    const MetricsRecord& m = o.metrics;
    j << (i ? "," : "") << "\n    {\"scene\": " << json_quote(o.spec.scene_name())
      << ", \"method\": " << json_quote(o.spec.method)
      << ", \"ablation\": " << json_quote(o.spec.ablation.empty() ? "full" : o.spec.ablation)
      << ", \"seed\": " << o.spec.seed << ", \"status\": " << json_quote(to_string(o.status))
      << ", \"resumed\": " << (o.resumed ? "true" : "false") << ", \"exit_code\": " << o.exit_code
      << ", \"wall_s\": " << json_number(o.wall_s) << ", \"reason\": " << json_quote(o.reason)
      << ", \"run_dir\": " << json_quote(o.spec.rel_dir());
    if (o.status == RunStatus::finished) {
      j << ",\n     \"metrics\": {\"success\": " << (m.success ? "true" : "false")
        << ", \"floors_total\": " << m.floors_total
        << ", \"floors_explored\": " << m.floors_explored
        << ", \"exploration_time_s\": " << json_number(m.exploration_time_s)
        << ", \"trajectory_length_m\": " << json_number(m.trajectory_length_m)
        << ", \"traversable_coverage\": " << json_number(m.traversable_coverage)
        << ", \"traversable_volume_m3\": " << json_number(m.traversable_volume_m3)
        << ", \"occupied_volume_m3\": " << json_number(m.occupied_volume_m3)
        << ", \"collisions\": " << json_number(m.collisions)
        << ", \"falls\": " << json_number(m.falls)
        << ", \"safety_stops\": " << json_number(m.safety_stops)
        << ", \"walking_time_s\": " << json_number(m.walking_time_s) << ", \"per_floor\": [";
      for (size_t f = 0; f < m.per_floor.size(); ++f)
        j << (f ? ", " : "") << "{\"z_m\": " << json_number(m.per_floor[f].z_m)
          << ", \"time_s\": " << json_number(m.per_floor[f].time_s)
          << ", \"traversable_coverage\": " << json_number(m.per_floor[f].traversable_coverage)
          << "}";
      j << "]}";
    }
    j << "}";
  }
  j << "\n  ],\n  \"groups\": [";
  const auto groups = group_runs(in.outcomes);
  const size_t nf = max_floors(in.outcomes);
  for (size_t i = 0; i < groups.size(); ++i) {
    const RunGroup& g = groups[i];
    j << (i ? "," : "") << "\n    {\"scene\": " << json_quote(g.scene)
      << ", \"method\": " << json_quote(g.method)
      << ", \"ablation\": " << json_quote(g.ablation.empty() ? "full" : g.ablation)
      << ", \"runs\": " << g.runs.size() << ", \"finished\": " << g.finished()
      << ", \"failed\": " << g.failed() << ", \"not_run\": " << g.not_run()
      << ", \"all_floors_explored\": ";
    size_t all = 0;
    for (const MetricsRecord* m : finished_metrics(g)) all += all_floors(*m);
    j << all << ",\n     \"exploration_time_s\": "
      << stat_json(stat_over(g, [](auto& m) { return m.exploration_time_s; }))
      << ", \"trajectory_length_m\": "
      << stat_json(stat_over(g, [](auto& m) { return m.trajectory_length_m; }))
      << ",\n     \"traversable_volume_m3\": "
      << stat_json(stat_over(g, [](auto& m) { return m.traversable_volume_m3; }))
      << ", \"occupied_volume_m3\": "
      << stat_json(stat_over(g, [](auto& m) { return m.occupied_volume_m3; }))
      << ",\n     \"traversable_coverage\": "
      << stat_json(stat_over(g, [](auto& m) { return m.traversable_coverage; }))
      << ", \"walking_time_s\": "
      << stat_json(stat_over(g, [](auto& m) { return m.walking_time_s; }))
      << ",\n     \"floor_time_s\": [";
    for (size_t f = 0; f < nf; ++f)
      j << (f ? ", " : "") << stat_json(stat_over(g, [f](auto& m) {
        const double t = floor_time(m, f);
        return t >= 0 ? t : kNaN;
      }));
    j << "], \"floor_coverage\": [";
    for (size_t f = 0; f < nf; ++f)
      j << (f ? ", " : "") << stat_json(stat_over(g, [f](auto& m) {
        return f < m.per_floor.size() ? m.per_floor[f].traversable_coverage : kNaN;
      }));
    j << "]}";
  }
  j << "\n  ],\n  \"plots\": {";
  for (size_t i = 0; i < in.plots.size(); ++i)
    j << (i ? ", " : "") << json_quote(in.plots[i].first) << ": " << json_quote(in.plots[i].second);
  j << "}\n}\n";
  return j.str();
}

std::vector<std::string> write_results(const std::string& dir,
                                       const std::vector<RunOutcome>& outcomes,
                                       const std::string& command) {
  std::filesystem::create_directories(dir);
  ResultsInput in{outcomes, command, {}};
  std::vector<std::string> written;
  const auto groups = group_runs(in.outcomes);
  std::vector<std::string> scenes;
  for (const auto& g : groups)
    if (std::find(scenes.begin(), scenes.end(), g.scene) == scenes.end()) scenes.push_back(g.scene);
  for (const auto& scene : scenes) {
    double t_end = 0;
    for (const auto& g : groups)
      if (g.scene == scene)
        for (const RunOutcome* r : g.runs)
          if (r->status == RunStatus::finished && !r->metrics.coverage_over_time.empty())
            t_end = std::max(t_end, r->metrics.coverage_over_time.back().first);
    if (t_end <= 0) continue;
    std::vector<CoverageCurve> curves;
    for (const auto& g : groups) {
      if (g.scene != scene || g.finished() == 0) continue;
      CoverageCurve c = mean_coverage_curve(g.runs, std::max(0.1, t_end / 400.0), t_end);
      c.label = g.variant();
      if (c.runs) curves.push_back(std::move(c));
    }
    const std::string file = "coverage_" + scene + ".png";
    write_coverage_plot(dir + "/" + file, scene + " (mean over seeds)", curves);
    in.plots.emplace_back(scene, file);
    written.push_back(dir + "/" + file);
  }
  auto write = [&](const std::string& name, const std::string& text) {
    const std::string path = dir + "/" + name;
    std::ofstream f(path);
    f << text;
    if (!f) throw std::runtime_error(path + ": cannot write");
    written.push_back(path);
  };
  write("results.md", results_markdown(in));
  write("results.csv", results_csv(in.outcomes));
  write("results.json", results_json(in));
  return written;
}

}  // namespace storey::tools::eval
