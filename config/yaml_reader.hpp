#pragma once
// A small validated reader from a YAML mapping into typed fields (yaml-cpp underneath).
//
// Each section of a configuration file is read by one SectionReader: every get() names a key,
// the destination field (which keeps its default when the key is absent), the accepted range,
// and whether the key is required. The reader remembers every key asked for, so that when it
// finishes, any key present in the file but never asked for is an error (a typo), reported with
// the nearest known key as a suggestion. Wrong types, missing required values and out-of-range
// numbers are errors too. Errors are collected, never thrown: one run reports all of them, each
// naming the file, the key path (`map.voxel_size_m`) and the 1-based line.
//
// Layering: a configuration may include other files; each file is read by its own readers in
// order (base first), so a later file overrides only the keys it names. Required keys are
// checked once all layers are read (ReadContext::check_required).
#include <yaml-cpp/yaml.h>

#include <array>
#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace storey::config {

// Where a value came from. line is 1-based; 0 means "no line" (whole file, or a default).
struct Location {
  std::string file;
  int line = 0;
};

// One problem found in a configuration, printable as `file:line: key: message`.
struct ConfigError {
  Location where;
  std::string key;  // dotted key path, e.g. "map.voxel_size_m"; empty for whole-file errors
  std::string message;
  std::string to_string() const;
};

// Accepted closed interval of a number; for angles read with get_deg it is in degrees.
struct Range {
  double min;
  double max;
};

enum class Need { kOptional, kRequired };

// A name accepted for an enumerated setting, and the value it stands for.
template <class E>
struct EnumName {
  std::string_view name;
  E value;
};

// Extra validation of a string value: returns an empty string when fine, else the reason.
using StringCheck = std::string (*)(const std::string&);

// State shared by all readers of one load: the errors, where each key was last set (for
// cross-field messages) and which required keys were asked for but never given.
class ReadContext {
 public:
  void error(Location where, std::string key, std::string message);
  const std::vector<ConfigError>& errors() const { return errors_; }
  std::vector<ConfigError> take_errors() { return std::move(errors_); }

  // Records that `key` was set at `where` (later layers override earlier ones).
  void set_origin(const std::string& key, Location where);
  // Where `key` was last set; if it never was, `fallback`.
  Location origin(const std::string& key, const Location& fallback) const;
  bool was_set(const std::string& key) const { return origins_.count(key) != 0; }
  const std::map<std::string, Location>& origins() const { return origins_; }
  // Order in which `key` was last set (layers are read base first, so a higher number is a
  // later layer); -1 if never set.
  long set_order(const std::string& key) const;

  // Every value key any reader asked for: the schema, as far as it was walked.
  void note_asked(const std::string& key) { asked_.insert(key); }
  const std::set<std::string>& asked() const { return asked_; }

  // Records that required `key` was asked for by a reader over the file at `where`.
  void note_required(const std::string& key, Location where);
  // Adds a "missing required value" error for every required key set in no layer.
  void check_required();

 private:
  std::vector<ConfigError> errors_;
  std::map<std::string, Location> origins_;
  std::map<std::string, long> set_order_;
  long next_order_ = 0;
  std::map<std::string, Location> required_;  // key -> last place it was asked for
  std::set<std::string> asked_;
};

// Reads one YAML mapping (a section). Non-copyable; finish() runs at the latest in the
// destructor and reports unknown and duplicate keys.
class SectionReader {
 public:
  // `node` may be undefined/null (section absent in this layer): every get() then leaves its
  // field untouched. `key_line` is the 1-based line of the key that introduced the section.
  SectionReader(YAML::Node node, std::string path, std::shared_ptr<const std::string> file,
                int key_line, ReadContext& ctx);
  SectionReader(const SectionReader&) = delete;
  SectionReader& operator=(const SectionReader&) = delete;
  SectionReader(SectionReader&& other) noexcept;
  ~SectionReader();

  // Numbers. Integers reject fractional values; all reject NaN/inf and values outside `range`.
  void get(std::string_view key, double& out, Range range, Need need = Need::kOptional);
  void get(std::string_view key, float& out, Range range, Need need = Need::kOptional);
  void get(std::string_view key, int& out, Range range, Need need = Need::kOptional);
  void get(std::string_view key, bool& out, Need need = Need::kOptional);
  void get(std::string_view key, std::string& out, StringCheck check = nullptr,
           Need need = Need::kOptional);

  // A list of strings of any length (e.g. peer addresses); each element passes `check`.
  void get(std::string_view key, std::vector<std::string>& out, StringCheck check = nullptr,
           Need need = Need::kOptional);

  // An angle written in degrees (the key must end in "_deg"), stored in radians.
  void get_deg(std::string_view key, double& out_rad, Range range_deg, Need need = Need::kOptional);

  // A fixed-size list of numbers, e.g. `xyz_m: [0.1, 0.0, 0.2]`; exactly N elements.
  template <std::size_t N>
  void get_list(std::string_view key, std::array<double, N>& out, Range range,
                Need need = Need::kOptional) {
    get_list_impl(key, std::span<double>(out), range, 1.0, need);
  }
  // Same, written in degrees (key ends in "_deg"), stored in radians.
  template <std::size_t N>
  void get_list_deg(std::string_view key, std::array<double, N>& out_rad, Range range_deg,
                    Need need = Need::kOptional) {
    get_list_impl(key, std::span<double>(out_rad), range_deg, kDegToRad, need);
  }

  // One of a fixed list of names, e.g. `type: vlp16`.
  template <class E, std::size_t N>
  void get_enum(std::string_view key, E& out, const EnumName<E> (&names)[N],
                Need need = Need::kOptional) {
    std::array<std::string_view, N> list{};
    for (std::size_t i = 0; i < N; ++i) list[i] = names[i].name;
    if (std::optional<std::size_t> i = get_choice(key, list, need)) out = names[*i].value;
  }

  // A nested mapping. The returned reader must be finished (or destroyed) by the caller.
  SectionReader section(std::string_view key, Need need = Need::kOptional);

  // Declares a key as known without reading it (handled elsewhere, e.g. `include`).
  void known(std::string_view key);

  // Reports keys present but never asked for, and duplicate keys. Idempotent.
  void finish();

  // Dotted path of a key in this section, e.g. "map.voxel_size_m".
  std::string path_of(std::string_view key) const;
  const std::string& path() const { return path_; }
  Location here(int line) const { return Location{*file_, line}; }

  static constexpr double kDegToRad = 0.017453292519943295;

 private:
  // Looks up `key`, marking it known; returns the value node and its line, or nothing when
  // absent (noting a required key) or null (an error).
  std::optional<std::pair<YAML::Node, int>> lookup(std::string_view key, Need need);
  bool parse_number(const YAML::Node& v, int line, const std::string& key, bool integer,
                    Range range, double& out);
  void get_number(std::string_view key, double& out, Range range, bool integer, Need need);
  void get_list_impl(std::string_view key, std::span<double> out, Range range, double scale,
                     Need need);
  std::optional<std::size_t> get_choice(std::string_view key,
                                        std::span<const std::string_view> names, Need need);

  // The mapping's entries, indexed once (yaml-cpp iteration is slow; sections are read key by
  // key). A non-scalar key (a list or mapping used as a key) has an empty name.
  struct Entry {
    std::string key;
    YAML::Node key_node;
    YAML::Node value;
    int line;
  };
  const Entry* find(std::string_view key) const;

  std::vector<Entry> entries_;
  std::string path_;
  std::shared_ptr<const std::string> file_;
  int key_line_ = 0;
  ReadContext* ctx_ = nullptr;
  std::set<std::string, std::less<>> known_;
  bool finished_ = false;
};

// Edit distance (optimal string alignment: insert, delete, substitute, swap neighbours).
std::size_t edit_distance(std::string_view a, std::string_view b);

// The candidate closest to `word`, if close enough to be a likely typo; else empty.
std::string closest_match(std::string_view word, const std::set<std::string, std::less<>>& known);

}  // namespace storey::config
