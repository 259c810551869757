#include "rt/trace.hpp"

#include <gtest/gtest.h>

#include <cctype>
#include <sstream>
#include <string>
#include <thread>

namespace storey::rt {
namespace {

// Minimal JSON well-formedness check (RFC 8259 grammar, no semantic checks).
class JsonChecker {
 public:
  explicit JsonChecker(const std::string& s) : s_(s) {}
  bool ok() {
    ws();
    if (!value()) return false;
    ws();
    return i_ == s_.size();
  }
  int objects = 0;

 private:
  bool value() {
    if (i_ >= s_.size()) return false;
    char c = s_[i_];
    if (c == '{') return object();
    if (c == '[') return array();
    if (c == '"') return string();
    if (c == '-' || std::isdigit(static_cast<unsigned char>(c))) return number();
    for (const char* lit : {"true", "false", "null"}) {
      if (s_.compare(i_, std::char_traits<char>::length(lit), lit) == 0) {
        i_ += std::char_traits<char>::length(lit);
        return true;
      }
    }
    return false;
  }
  bool object() {
    ++objects;
    ++i_;
    ws();
    if (peek('}')) return ++i_, true;
    for (;;) {
      ws();
      if (!string()) return false;
      ws();
      if (!peek(':')) return false;
      ++i_;
      ws();
      if (!value()) return false;
      ws();
      if (peek('}')) return ++i_, true;
      if (!peek(',')) return false;
      ++i_;
    }
  }
  bool array() {
    ++i_;
    ws();
    if (peek(']')) return ++i_, true;
    for (;;) {
      ws();
      if (!value()) return false;
      ws();
      if (peek(']')) return ++i_, true;
      if (!peek(',')) return false;
      ++i_;
    }
  }
  bool string() {
    if (!peek('"')) return false;
    for (++i_; i_ < s_.size(); ++i_) {
      const unsigned char c = s_[i_];
      if (c == '"') return ++i_, true;
      if (c < 0x20) return false;
      if (c == '\\') ++i_;
    }
    return false;
  }
  bool number() {
    const std::size_t start = i_;
    if (peek('-')) ++i_;
    while (i_ < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[i_])) || s_[i_] == '.' ||
                              s_[i_] == 'e' || s_[i_] == 'E' || s_[i_] == '+' || s_[i_] == '-'))
      ++i_;
    return i_ > start;
  }
  bool peek(char c) const { return i_ < s_.size() && s_[i_] == c; }
  void ws() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  const std::string& s_;
  std::size_t i_ = 0;
};

TEST(TraceRing, KeepsNewestAndCounts) {
  TraceRing ring(4);
  for (int i = 0; i < 10; ++i) ring.record("task", 1, 1000 * i, 10);
  EXPECT_EQ(ring.recorded(), 10u);
  EXPECT_EQ(ring.overwritten(), 6u);
  const auto ev = ring.events();
  ASSERT_EQ(ev.size(), 4u);
  EXPECT_EQ(ev.front().start_ns, 6000);
  EXPECT_EQ(ev.back().start_ns, 9000);
}

TEST(TraceRing, ChromeJsonIsWellFormed) {
  TraceRing ring(16);
  ring.set_thread_name(1, "map \"10 Hz\"");
  ring.record("insert", 1, 1'234'567, 890);
  ring.record("weird\\name\n", 2, 2'000'000, 5);
  { TraceScope scope(&ring, "scope", 3); }
  std::ostringstream os;
  ring.write_chrome_json(os);
  const std::string json = os.str();
  JsonChecker check(json);
  EXPECT_TRUE(check.ok()) << json;
  EXPECT_EQ(check.objects, 1 + 1 + 3 + 1);  // root, metadata + its args, 3 events
  EXPECT_NE(json.find("\"ts\":1234.567,\"dur\":0.890"), std::string::npos) << json;
  EXPECT_NE(json.find("\"ph\":\"X\""), std::string::npos);
}

TEST(TraceRing, EmptyJsonAndBadPath) {
  TraceRing ring(2);
  std::ostringstream os;
  ring.write_chrome_json(os);
  EXPECT_TRUE(JsonChecker(os.str()).ok()) << os.str();
  std::string err;
  EXPECT_FALSE(ring.write_chrome_json("/nonexistent-dir/trace.json", &err));
  EXPECT_NE(err.find("/nonexistent-dir/trace.json"), std::string::npos);
}

TEST(TraceRing, ConcurrentWritersAndExporter) {
  TraceRing ring(1024);
  std::thread writers[2];
  for (int w = 0; w < 2; ++w) {
    writers[w] = std::thread([&ring, w] {
      for (int i = 0; i < 50'000; ++i) ring.record(w ? "b" : "a", w + 1, i, w + 1);
    });
  }
  std::size_t bad = 0;
  for (int k = 0; k < 50; ++k) {
    for (const auto& e : ring.events()) {
      // Every exported event is one whole write: name, tid and dur agree.
      const int w = static_cast<int>(e.tid) - 1;
      if ((w != 0 && w != 1) || e.dur_ns != w + 1 || e.name[0] != (w ? 'b' : 'a')) ++bad;
    }
  }
  for (auto& t : writers) t.join();
  EXPECT_EQ(bad, 0u);
  EXPECT_EQ(ring.recorded(), 100'000u);
  EXPECT_LE(ring.events().size(), 1024u);
  EXPECT_GE(ring.events().size() + ring.dropped(), 1024u);  // a drop may leave an old slot
}

}  // namespace
}  // namespace storey::rt
