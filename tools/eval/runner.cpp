#include "tools/eval/runner.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace storey::tools::eval {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

volatile std::sig_atomic_t g_stop = 0;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

struct Running {
  size_t index;  // into specs
  pid_t pid;
  Clock::time_point start;
  std::string staging, final_dir;
  double sim_t = -1.0;  // simulated seconds reached, from the child's progress lines
  Clock::time_point polled{};
};

struct RunningInfo {
  double elapsed_s, sim_t, limit_s;
};

// The progress bar: one line on a terminal (rewritten with '\r'), otherwise one line per run.
class Progress {
 public:
  Progress(FILE* out, size_t total, size_t resumed, int jobs)
      : out_(out),
        tty_(out && isatty(fileno(out))),
        total_(total),
        resumed_(resumed),
        jobs_(std::max(1, jobs)) {}

  void finished(const RunOutcome& o, double wall_s) {
    ++done_;
    if (o.status == RunStatus::failed) ++failed_;
    if (o.status == RunStatus::finished) {
      ++timed_;
      wall_sum_ += wall_s;
    }
    if (!out_) return;
    const std::string name = o.spec.rel_dir().substr(5);  // without "runs/"
    if (o.status == RunStatus::failed) {
      clear();
      std::fprintf(out_, "storey-eval: %s failed: %s\n", name.c_str(), o.reason.c_str());
    } else if (!tty_) {
      std::fprintf(out_, "storey-eval: %s %s (%.0f s)  %s\n", name.c_str(), to_string(o.status),
                   wall_s, line().c_str());
    }
    draw(true);
  }
  // Running children's elapsed wall and simulated seconds, for the ETA.
  void set_running(std::vector<RunningInfo> r) { running_ = std::move(r); }
  void draw(bool force = false) {
    if (!out_ || !tty_) return;
    if (!force && seconds_since(last_draw_) < 0.5) return;
    last_draw_ = Clock::now();
    std::fprintf(out_, "\r%s\033[K", line().c_str());
    std::fflush(out_);
  }
  void end() {
    if (out_ && tty_) std::fprintf(out_, "\n");
  }

 private:
  void clear() {
    if (tty_) std::fprintf(out_, "\r\033[K");
  }
  std::string line() const {
    const size_t finished = resumed_ + done_;
    const int width = 24;
    const int fill = total_ ? int(double(width) * double(finished) / double(total_)) : width;
    std::string bar(size_t(fill), '#');
    bar.resize(size_t(width), '.');
    char b[256];
    std::snprintf(b, sizeof b, "[%s] %zu/%zu runs", bar.c_str(), finished, total_);
    std::string s = b;
    if (resumed_) s += " (" + std::to_string(resumed_) + " resumed)";
    if (failed_) s += ", " + std::to_string(failed_) + " failed";
    s += ", " + std::to_string(running_.size()) + " running, " +
         format_duration(seconds_since(start_)) + " elapsed, ETA " + eta();
    return s;
  }
  // Mean wall time of the runs finished so far (instant failures excluded), spread over the
  // job slots: what is left of the running ones plus the ones not started. Before any run has
  // finished: each running child's pace (simulated / wall seconds) extrapolated to the time
  // limit, an upper bound since explorations usually complete earlier ("<= ").
  std::string eta() const {
    const size_t started = done_ + running_.size();
    const size_t to_run = total_ - resumed_;
    const double not_started = double(to_run > started ? to_run - started : 0);
    if (timed_ > 0) {
      const double mean = wall_sum_ / double(timed_);
      double work = not_started * mean;
      for (const auto& r : running_) work += std::max(0.0, mean - r.elapsed_s);
      return format_duration(work / double(jobs_));
    }
    double work = 0, total_sum = 0;
    size_t paced = 0;
    for (const auto& r : running_) {
      if (r.sim_t < 1.0) continue;
      const double total = r.elapsed_s * r.limit_s / r.sim_t;
      work += std::max(0.0, total - r.elapsed_s);
      total_sum += total;
      ++paced;
    }
    if (paced == 0) return "--";
    work += not_started * total_sum / double(paced);
    return "<= " + format_duration(work / double(jobs_));
  }

  FILE* out_;
  bool tty_;
  size_t total_, resumed_;
  int jobs_;
  size_t done_ = 0, failed_ = 0, timed_ = 0;
  double wall_sum_ = 0.0;
  std::vector<RunningInfo> running_;
  Clock::time_point start_ = Clock::now(), last_draw_{};
};

bool metrics_complete(const std::string& dir) {
  return read_metrics_json(dir + "/metrics.json", nullptr).has_value();
}

}  // namespace

std::string format_duration(double s) {
  if (!(s >= 0)) s = 0;
  const long t = long(s + 0.5);
  char b[32];
  if (t >= 3600)
    std::snprintf(b, sizeof b, "%ldh%02ldm", t / 3600, (t / 60) % 60);
  else if (t >= 60)
    std::snprintf(b, sizeof b, "%ldm%02lds", t / 60, t % 60);
  else
    std::snprintf(b, sizeof b, "%lds", t);
  return b;
}

void Runner::request_stop() {
  g_stop = 1;
}
bool Runner::stop_requested() {
  return g_stop != 0;
}
void Runner::clear_stop() {
  g_stop = 0;
}

std::vector<RunOutcome> Runner::run(const std::vector<RunSpec>& specs) {
  std::vector<RunOutcome> out(specs.size());
  std::vector<size_t> pending;
  for (size_t i = 0; i < specs.size(); ++i) {
    const std::string dir = o_.out_dir + "/" + specs[i].rel_dir();
    if (metrics_complete(dir)) {
      out[i] = load_outcome(specs[i], dir);
      out[i].resumed = true;
    } else {
      out[i].spec = specs[i];
      pending.push_back(i);
    }
  }
  if (o_.progress)
    std::fprintf(o_.progress,
                 "storey-eval: %zu of %zu runs already finished (resumed), %zu to run\n",
                 specs.size() - pending.size(), specs.size(), pending.size());
  Progress progress(o_.progress, specs.size(), specs.size() - pending.size(), o_.jobs);
  // Reads the children's progress lines every 2 s (only for the ETA).
  auto running_info = [&](std::vector<Running>& rs) {
    std::vector<RunningInfo> v;
    for (auto& r : rs) {
      if (seconds_since(r.polled) > 2.0) {
        r.polled = Clock::now();
        r.sim_t = last_simulated_time(r.staging + "/log.txt");
      }
      v.push_back(
          {seconds_since(r.start), r.sim_t, o_.time_limits.for_scene(specs[r.index].scene_name())});
    }
    return v;
  };
  std::vector<Running> running;
  size_t next = 0;

  auto start_one = [&](size_t i) {
    const RunSpec& spec = specs[i];
    Running r{i,
              -1,
              Clock::now(),
              o_.out_dir + "/" + spec.rel_dir() + ".partial",
              o_.out_dir + "/" + spec.rel_dir(),
              -1.0,
              Clock::now()};
    std::error_code ec;
    fs::remove_all(r.staging, ec);
    fs::create_directories(r.staging, ec);
    if (ec) throw std::runtime_error(r.staging + ": cannot create (" + ec.message() + ")");
    std::vector<std::string> args =
        spec.sim_args(o_.time_limits.for_scene(spec.scene_name()), r.staging, o_.config);
    args.insert(args.begin(), o_.storey);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const std::string log = r.staging + "/log.txt";
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, 2, 1);
    // Checked first: some posix_spawn implementations report a failed exec only as exit 127.
    const int rc = access(o_.storey.c_str(), X_OK) != 0
                       ? errno
                       : posix_spawn(&r.pid, o_.storey.c_str(), &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) {
      // Recorded like any failed run, so the rest of the matrix still runs.
      RunOutcome f;
      f.spec = spec;
      f.status = RunStatus::failed;
      f.reason = "cannot start " + o_.storey + ": " + std::strerror(rc);
      write_eval_record(f, r.staging, args);
      fs::remove_all(r.final_dir, ec);
      fs::rename(r.staging, r.final_dir, ec);
      out[i] = f;
      progress.finished(f, 0.0);
      return;
    }
    running.push_back(std::move(r));
  };

  auto finish_one = [&](const Running& r, int status) {
    const RunSpec& spec = specs[r.index];
    const double wall = seconds_since(r.start);
    const bool signalled = WIFSIGNALED(status);
    RunOutcome o;
    o.spec = spec;
    o.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    o.wall_s = wall;
    std::error_code ec;
    if (signalled && g_stop) {
      // Interrupted by the user: nothing to keep; the next invocation starts it afresh.
      fs::remove_all(r.staging, ec);
      out[r.index] = o;
      return;
    }
    if (metrics_complete(r.staging)) {
      o.status = RunStatus::finished;
    } else {
      o.status = RunStatus::failed;
      const std::string last = last_line(r.staging + "/log.txt");
      if (signalled)
        o.reason = "killed by signal " + std::to_string(WTERMSIG(status)) +
                   (last.empty() ? std::string() : " (last line: " + last + ")");
      else
        o.reason = last.empty() ? "exit code " + std::to_string(o.exit_code) +
                                      " without metrics.json or a message"
                                : last;
    }
    std::vector<std::string> cmd =
        spec.sim_args(o_.time_limits.for_scene(spec.scene_name()), r.final_dir, o_.config);
    cmd.insert(cmd.begin(), o_.storey);
    write_eval_record(o, r.staging, cmd);
    fs::remove_all(r.final_dir, ec);
    fs::rename(r.staging, r.final_dir, ec);
    if (ec)
      throw std::runtime_error(r.final_dir + ": cannot move the finished run (" + ec.message() +
                               ")");
    // The folder is the one source of truth (the end reason comes from report.md).
    RunOutcome loaded = load_outcome(spec, r.final_dir);
    if (o.status == RunStatus::failed && loaded.status != RunStatus::failed) loaded = o;
    // A record without report.md (the child failed while writing it): its last words.
    if (loaded.reason.empty() && o.exit_code != 0)
      loaded.reason = last_line(r.final_dir + "/log.txt");
    loaded.exit_code = o.exit_code;
    loaded.wall_s = wall;
    out[r.index] = loaded;
    progress.set_running(running_info(running));
    progress.finished(loaded, wall);
  };

  const int jobs = std::max(1, o_.jobs);
  bool forwarded = false;
  while (next < pending.size() || !running.empty()) {
    while (!g_stop && next < pending.size() && int(running.size()) < jobs)
      start_one(pending[next++]);
    if (g_stop && !forwarded) {
      // A signal sent to storey-eval alone (kill, systemd) reaches the children here; Ctrl-C
      // reached them already (same process group) and this second one is harmless.
      next = pending.size();  // the rest stay not_run
      for (const auto& r : running) kill(r.pid, SIGTERM);
      forwarded = true;
    }
    bool reaped = false;
    for (size_t k = 0; k < running.size();) {
      int status = 0;
      const pid_t p = waitpid(running[k].pid, &status, WNOHANG);
      if (p == running[k].pid || (p < 0 && errno == ECHILD)) {
        const Running r = running[k];
        running.erase(running.begin() + long(k));
        finish_one(r, p < 0 ? (SIGKILL & 0x7f) : status);
        reaped = true;
      } else {
        ++k;
      }
    }
    progress.set_running(running_info(running));
    progress.draw();
    if (!reaped && !running.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  progress.draw(true);
  progress.end();
  return out;
}

}  // namespace storey::tools::eval
