// storey-eval (DESIGN §5, §7): the paper's Section V regenerated in the simulator. Expands the
// matrix, runs `storey sim` children in parallel (resumable), then writes the tables and plots.
#include <limits.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/file.h>

#include "tools/eval/eval_options.hpp"
#include "tools/eval/results.hpp"
#include "tools/eval/runner.hpp"

namespace eval = storey::tools::eval;
namespace fs = std::filesystem;

namespace {

extern "C" void on_interrupt(int) {
  eval::Runner::request_stop();
}

// The `storey` beside this executable (both land in the build folder's root).
std::string storey_next_to_me() {
  char buf[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return "storey";
  buf[n] = '\0';
  return (fs::path(buf).parent_path() / "storey").string();
}

std::string shell_words(int argc, char** argv) {
  std::string s = "storey-eval";
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    const bool plain = a.find_first_of(" \t'\"$`\\") == std::string::npos && !a.empty();
    // Appended piecewise: GCC 12 warns (-Wrestrict, a false positive) on "'" + a + "'".
    s += plain ? " " : " '";
    s += a;
    if (!plain) s += '\'';
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  const eval::ParseResult p =
      eval::parse_eval_args(std::vector<std::string>(argv + 1, argv + argc));
  if (!p.ok()) {
    std::fprintf(stderr, "storey-eval: %s\n", p.error.c_str());
    return 2;
  }
  const eval::EvalOptions& o = p.options;
  if (o.help) {
    eval::print_eval_usage(stdout);
    return 0;
  }
  const std::string storey = o.storey.empty() ? storey_next_to_me() : o.storey;
  if (!o.report_only && access(storey.c_str(), X_OK) != 0) {
    std::fprintf(stderr,
                 "storey-eval: --storey %s: not an executable (build the `storey` target with "
                 "-DSTOREY_BUILD_TOOLS=ON, or pass --storey PATH)\n",
                 storey.c_str());
    return 2;
  }
  std::error_code ec;
  fs::create_directories(o.out_dir, ec);
  if (ec) {
    std::fprintf(stderr, "storey-eval: --out %s: %s\n", o.out_dir.c_str(), ec.message().c_str());
    return 2;
  }
  // One storey-eval per output folder: two would run the same seeds into the same folders.
  const std::string lock = o.out_dir + "/.storey-eval.lock";
  const int lock_fd = open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd < 0 || flock(lock_fd, LOCK_EX | LOCK_NB) != 0) {
    std::fprintf(stderr, "storey-eval: --out %s: in use by another storey-eval (%s)\n",
                 o.out_dir.c_str(), lock.c_str());
    return 2;
  }

  const std::vector<eval::RunSpec> specs = eval::expand_matrix(o.groups, o.seeds);
  const int jobs = o.jobs > 0 ? o.jobs : int(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<eval::RunOutcome> outcomes;
  try {
    if (o.report_only) {
      for (const auto& s : specs)
        outcomes.push_back(eval::load_outcome(s, o.out_dir + "/" + s.rel_dir()));
      for (auto& r : outcomes) r.resumed = r.status == eval::RunStatus::finished;
    } else {
      std::fprintf(stderr,
                   "storey-eval: %zu runs (%zu scene/method/ablation x %zu seeds), %d jobs, "
                   "time limit %s, %s, into %s\n",
                   specs.size(), o.seeds.empty() ? 0 : specs.size() / o.seeds.size(),
                   o.seeds.size(), jobs, o.time_limits.describe().c_str(), storey.c_str(),
                   o.out_dir.c_str());
      // Each run reads ./config/default.yaml when no --config is given: that file belongs to the
      // working tree, which need not be the code another --storey was built from (session 35:
      // a key added to the tree's file failed 43 runs of a binary built before it).
      if (!o.storey.empty() && o.config.empty())
        std::fprintf(stderr,
                     "storey-eval: warning: --storey without --config: every run reads "
                     "config/default.yaml from %s, which may not match that build\n",
                     std::filesystem::current_path().c_str());
      struct sigaction sa {};
      sa.sa_handler = on_interrupt;
      sa.sa_flags = SA_RESETHAND;  // a second Ctrl-C kills storey-eval at once
      sigaction(SIGINT, &sa, nullptr);
      sigaction(SIGTERM, &sa, nullptr);
      eval::Runner runner({storey, jobs, o.out_dir, o.time_limits, o.config, stderr});
      outcomes = runner.run(specs);
    }
    const auto files = eval::write_results(o.out_dir, outcomes, shell_words(argc, argv));
    size_t fin = 0, fail = 0, nrun = 0;
    for (const auto& r : outcomes) {
      fin += r.status == eval::RunStatus::finished;
      fail += r.status == eval::RunStatus::failed;
      nrun += r.status == eval::RunStatus::not_run;
    }
    std::fprintf(stderr, "storey-eval: %zu finished, %zu failed, %zu not run%s\n", fin, fail, nrun,
                 eval::Runner::stop_requested() ? " (interrupted: run again to resume)" : "");
    std::printf("%s/results.md\n", o.out_dir.c_str());
    // Failed runs are results too (a method storey sim refuses); interrupted ones are not.
    return eval::Runner::stop_requested() ? 130 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "storey-eval: %s\n", e.what());
    return 1;
  }
}
