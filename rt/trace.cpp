#include "rt/trace.hpp"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "rt/clock.hpp"

namespace storey::rt {

TraceRing::TraceRing(std::size_t capacity)
    : capacity_(capacity), slots_(capacity ? new Slot[capacity] : nullptr) {
  if (capacity == 0) throw std::invalid_argument("TraceRing: capacity must be >= 1");
}

std::vector<TraceEvent> TraceRing::events() const {
  std::vector<TraceEvent> out;
  const std::uint64_t head = head_.load(std::memory_order_acquire);
  const std::uint64_t first = head > capacity_ ? head - capacity_ : 0;
  out.reserve(static_cast<std::size_t>(head - first));
  for (std::uint64_t i = first; i < head; ++i) {
    const Slot& s = slots_[i % capacity_];
    const std::uint64_t s1 = s.seq.load(std::memory_order_acquire);
    if (s1 != 2 * i + 2) continue;  // being written, or already overwritten by a newer event
    TraceEvent e{s.name.load(std::memory_order_relaxed), s.tid.load(std::memory_order_relaxed),
                 s.start.load(std::memory_order_relaxed), s.dur.load(std::memory_order_relaxed)};
    std::atomic_thread_fence(std::memory_order_acquire);
    if (s.seq.load(std::memory_order_relaxed) != s1 || e.name == nullptr) continue;
    out.push_back(e);
  }
  std::stable_sort(out.begin(), out.end(), [](const TraceEvent& a, const TraceEvent& b) {
    return a.start_ns < b.start_ns;
  });
  return out;
}

namespace {

void write_json_string(std::ostream& out, const char* s) {
  out << '"';
  for (; s && *s; ++s) {
    const unsigned char c = static_cast<unsigned char>(*s);
    if (c == '"' || c == '\\') {
      out << '\\' << *s;
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out << buf;
    } else {
      out << *s;
    }
  }
  out << '"';
}

// ns -> microseconds with ns precision, without going through a double.
void write_us(std::ostream& out, std::int64_t ns) {
  char buf[48];
  const char* sign = ns < 0 ? "-" : "";
  const std::uint64_t a =
      ns < 0 ? 0 - static_cast<std::uint64_t>(ns) : static_cast<std::uint64_t>(ns);
  std::snprintf(buf, sizeof buf, "%s%" PRIu64 ".%03" PRIu64, sign, a / 1000, a % 1000);
  out << buf;
}

}  // namespace

void TraceRing::write_chrome_json(std::ostream& out) const {
  out << "{\"displayTimeUnit\":\"ns\",\"traceEvents\":[";
  bool first = true;
  for (std::uint32_t tid = 0; tid < kMaxThreadNames; ++tid) {
    const char* name = thread_names_[tid].load(std::memory_order_acquire);
    if (!name) continue;
    out << (first ? "\n" : ",\n")
        << "{\"ph\":\"M\",\"name\":\"thread_name\",\"pid\":1,\"tid\":" << tid
        << ",\"args\":{\"name\":";
    write_json_string(out, name);
    out << "}}";
    first = false;
  }
  for (const TraceEvent& e : events()) {
    out << (first ? "\n" : ",\n") << "{\"ph\":\"X\",\"name\":";
    write_json_string(out, e.name);
    out << ",\"pid\":1,\"tid\":" << e.tid << ",\"ts\":";
    write_us(out, e.start_ns);
    out << ",\"dur\":";
    write_us(out, e.dur_ns);
    out << '}';
    first = false;
  }
  out << "\n]}\n";
}

bool TraceRing::write_chrome_json(const std::string& path, std::string* error) const {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (f) write_chrome_json(f);
  if (f) f.flush();
  if (!f) {
    if (error) *error = "cannot write trace file '" + path + "'";
    return false;
  }
  return true;
}

TraceScope::TraceScope(TraceRing* ring, const char* name, std::uint32_t tid) noexcept
    : ring_(ring), name_(name), tid_(tid), start_(ring ? monotonic_now_ns() : 0) {}

TraceScope::~TraceScope() {
  if (ring_) ring_->record(name_, tid_, start_, monotonic_now_ns() - start_);
}

}  // namespace storey::rt
