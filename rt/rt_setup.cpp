#include "rt/rt_setup.hpp"

#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace storey::rt {

std::string SetupStatus::message() const {
  if (ok()) return "ok";
  const char* name = error == EPERM ? " (EPERM)" : error == EINVAL ? " (EINVAL)" : "";
  return std::string(what) + ": " + std::strerror(error) + name;
}

SetupStatus lock_memory() noexcept {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) return {errno, "mlockall"};
  return {};
}

SetupStatus set_fifo(int priority, pthread_t thread) noexcept {
  if (priority < sched_get_priority_min(SCHED_FIFO) ||
      priority > sched_get_priority_max(SCHED_FIFO)) {
    return {EINVAL, "set_fifo: priority out of 1..99"};
  }
  sched_param p{};
  p.sched_priority = priority;
  // pthread_* return the error instead of setting errno.
  if (int e = pthread_setschedparam(thread, SCHED_FIFO, &p)) return {e, "pthread_setschedparam"};
  return {};
}

SetupStatus pin_cpu(int cpu, pthread_t thread) noexcept {
  const long n = sysconf(_SC_NPROCESSORS_CONF);
  if (cpu < 0 || cpu >= CPU_SETSIZE || (n > 0 && cpu >= n)) {
    return {EINVAL, "pin_cpu: no such CPU"};
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (int e = pthread_setaffinity_np(thread, sizeof set, &set)) {
    return {e, "pthread_setaffinity_np"};
  }
  return {};
}

}  // namespace storey::rt
