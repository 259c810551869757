#include "config/yaml_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <utility>

namespace storey::config {

namespace {

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// What a node is, for "expected X, got Y" messages.
std::string describe(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Map:
      return "a mapping";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Scalar:
      return n.Tag() == "!" ? "the string \"" + n.Scalar() + "\"" : "'" + n.Scalar() + "'";
    case YAML::NodeType::Null:
      return "nothing";
    default:
      return "an undefined value";
  }
}

int line_of(const YAML::Node& n, int fallback) {
  const YAML::Mark m = n.Mark();
  return m.is_null() ? fallback : m.line + 1;
}

bool is_non_finite_literal(std::string_view s) {
  std::string lower;
  for (char c : s) lower.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  if (!lower.empty() && (lower[0] == '+' || lower[0] == '-')) lower.erase(0, 1);
  return lower == ".inf" || lower == "inf" || lower == ".nan" || lower == "nan" ||
         lower == "infinity";
}

// Parses the whole of `s` as T; leading '+' allowed.
template <class T>
bool parse_all(std::string_view s, T& out) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const char* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(s.data(), end, out);
  return ec == std::errc() && ptr == end;
}

}  // namespace

std::string ConfigError::to_string() const {
  std::string s = where.file;
  if (where.line > 0) s.append(":").append(std::to_string(where.line));
  s.append(": ");
  if (!key.empty()) s.append(key).append(": ");
  s.append(message);
  return s;
}

// ---- ReadContext ---------------------------------------------------------------------------

void ReadContext::error(Location where, std::string key, std::string message) {
  errors_.push_back(ConfigError{std::move(where), std::move(key), std::move(message)});
}

void ReadContext::set_origin(const std::string& key, Location where) {
  origins_[key] = std::move(where);
  set_order_[key] = next_order_++;
}

long ReadContext::set_order(const std::string& key) const {
  auto it = set_order_.find(key);
  return it == set_order_.end() ? -1 : it->second;
}

Location ReadContext::origin(const std::string& key, const Location& fallback) const {
  auto it = origins_.find(key);
  return it == origins_.end() ? fallback : it->second;
}

void ReadContext::note_required(const std::string& key, Location where) {
  required_[key] = std::move(where);
}

void ReadContext::check_required() {
  for (const auto& [key, where] : required_) {
    if (!was_set(key)) error(where, key, "missing required value");
  }
}

// ---- SectionReader -------------------------------------------------------------------------

SectionReader::SectionReader(YAML::Node node, std::string path,
                             std::shared_ptr<const std::string> file, int key_line,
                             ReadContext& ctx)
    : path_(std::move(path)), file_(std::move(file)), key_line_(key_line), ctx_(&ctx) {
  if (!node.IsMap()) return;
  entries_.reserve(node.size());
  for (const auto& kv : node) {
    entries_.push_back(Entry{kv.first.IsScalar() ? kv.first.Scalar() : std::string(), kv.first,
                             kv.second, line_of(kv.first, key_line_)});
  }
}

const SectionReader::Entry* SectionReader::find(std::string_view key) const {
  for (const Entry& e : entries_) {
    if (e.key == key && e.key_node.IsScalar()) return &e;
  }
  return nullptr;
}

SectionReader::SectionReader(SectionReader&& other) noexcept
    : entries_(std::move(other.entries_)),
      path_(std::move(other.path_)),
      file_(std::move(other.file_)),
      key_line_(other.key_line_),
      ctx_(other.ctx_),
      known_(std::move(other.known_)),
      finished_(other.finished_) {
  other.finished_ = true;
}

SectionReader::~SectionReader() {
  finish();
}

std::string SectionReader::path_of(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

void SectionReader::known(std::string_view key) {
  known_.emplace(key);
}

std::optional<std::pair<YAML::Node, int>> SectionReader::lookup(std::string_view key, Need need) {
  known_.emplace(key);
  ctx_->note_asked(path_of(key));
  if (const Entry* e = find(key)) {
    if (e->value.IsNull()) {
      ctx_->error(here(e->line), path_of(key), "missing value");
      return std::nullopt;
    }
    return std::make_pair(e->value, e->line);
  }
  if (need == Need::kRequired) ctx_->note_required(path_of(key), here(key_line_));
  return std::nullopt;
}

bool SectionReader::parse_number(const YAML::Node& v, int line, const std::string& key,
                                 bool integer, Range range, double& out) {
  const char* expected = integer ? "expected an integer" : "expected a number";
  if (!v.IsScalar() || v.Tag() == "!") {
    ctx_->error(here(line_of(v, line)), key, std::string(expected) + ", got " + describe(v));
    return false;
  }
  const std::string& s = v.Scalar();
  double value = 0.0;
  if (integer) {
    long long i = 0;
    if (!parse_all(s, i)) {
      double d = 0.0;
      const bool number = parse_all(s, d) || is_non_finite_literal(s);
      ctx_->error(here(line_of(v, line)), key,
                  std::string(expected) + ", got " + (number ? s : describe(v)));
      return false;
    }
    value = static_cast<double>(i);
  } else {
    if (is_non_finite_literal(s)) {
      ctx_->error(here(line_of(v, line)), key, "must be a finite number, got " + s);
      return false;
    }
    if (!parse_all(s, value)) {
      ctx_->error(here(line_of(v, line)), key, std::string(expected) + ", got " + describe(v));
      return false;
    }
  }
  if (!(value >= range.min && value <= range.max)) {
    ctx_->error(here(line_of(v, line)), key,
                s + " is out of range [" + format_number(range.min) + ", " +
                    format_number(range.max) + "]");
    return false;
  }
  out = value;
  return true;
}

void SectionReader::get_number(std::string_view key, double& out, Range range, bool integer,
                               Need need) {
  auto found = lookup(key, need);
  if (!found) return;
  const std::string path = path_of(key);
  double value = 0.0;
  if (parse_number(found->first, found->second, path, integer, range, value)) {
    out = value;
    ctx_->set_origin(path, here(found->second));
  }
}

void SectionReader::get(std::string_view key, double& out, Range range, Need need) {
  get_number(key, out, range, false, need);
}

void SectionReader::get(std::string_view key, float& out, Range range, Need need) {
  double v = out;
  get_number(key, v, range, false, need);
  out = static_cast<float>(v);
}

void SectionReader::get(std::string_view key, int& out, Range range, Need need) {
  double v = out;
  get_number(key, v, range, true, need);
  out = static_cast<int>(v);
}

void SectionReader::get(std::string_view key, bool& out, Need need) {
  auto found = lookup(key, need);
  if (!found) return;
  const auto& [v, line] = *found;
  bool b = false;
  if (!v.IsScalar() || v.Tag() == "!" || !YAML::convert<bool>::decode(v, b)) {
    ctx_->error(here(line_of(v, line)), path_of(key), "expected true or false, got " + describe(v));
    return;
  }
  out = b;
  ctx_->set_origin(path_of(key), here(line));
}

void SectionReader::get(std::string_view key, std::string& out, StringCheck check, Need need) {
  auto found = lookup(key, need);
  if (!found) return;
  const auto& [v, line] = *found;
  if (!v.IsScalar()) {
    ctx_->error(here(line_of(v, line)), path_of(key), "expected a string, got " + describe(v));
    return;
  }
  if (check != nullptr) {
    if (std::string why = check(v.Scalar()); !why.empty()) {
      ctx_->error(here(line), path_of(key), why);
      return;
    }
  }
  out = v.Scalar();
  ctx_->set_origin(path_of(key), here(line));
}

void SectionReader::get(std::string_view key, std::vector<std::string>& out, StringCheck check,
                        Need need) {
  auto found = lookup(key, need);
  if (!found) return;
  const auto& [v, line] = *found;
  const std::string path = path_of(key);
  if (!v.IsSequence()) {
    ctx_->error(here(line_of(v, line)), path, "expected a list of strings, got " + describe(v));
    return;
  }
  std::vector<std::string> values;
  bool ok = true;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const YAML::Node e = v[i];
    const std::string element = path + "[" + std::to_string(i) + "]";
    if (!e.IsScalar()) {
      ctx_->error(here(line_of(e, line)), element, "expected a string, got " + describe(e));
      ok = false;
      continue;
    }
    if (check != nullptr) {
      if (std::string why = check(e.Scalar()); !why.empty()) {
        ctx_->error(here(line_of(e, line)), element, why);
        ok = false;
        continue;
      }
    }
    values.push_back(e.Scalar());
  }
  if (!ok) return;
  out = std::move(values);
  ctx_->set_origin(path, here(line));
}

void SectionReader::get_deg(std::string_view key, double& out_rad, Range range_deg, Need need) {
  double deg = out_rad / kDegToRad;
  auto found = lookup(key, need);
  if (!found) return;
  const std::string path = path_of(key);
  if (parse_number(found->first, found->second, path, false, range_deg, deg)) {
    out_rad = deg * kDegToRad;
    ctx_->set_origin(path, here(found->second));
  }
}

void SectionReader::get_list_impl(std::string_view key, std::span<double> out, Range range,
                                  double scale, Need need) {
  auto found = lookup(key, need);
  if (!found) return;
  const auto& [v, line] = *found;
  const std::string path = path_of(key);
  const std::string expected = "expected a list of " + std::to_string(out.size()) + " numbers";
  if (!v.IsSequence()) {
    ctx_->error(here(line_of(v, line)), path, expected + ", got " + describe(v));
    return;
  }
  if (v.size() != out.size()) {
    ctx_->error(here(line_of(v, line)), path,
                expected + ", got " + std::to_string(v.size()) + " elements");
    return;
  }
  std::vector<double> values(out.size());
  bool ok = true;
  for (std::size_t i = 0; i < out.size(); ++i) {
    ok = parse_number(v[i], line, path + "[" + std::to_string(i) + "]", false, range, values[i]) &&
         ok;
  }
  if (!ok) return;
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = values[i] * scale;
  ctx_->set_origin(path, here(line));
}

std::optional<std::size_t> SectionReader::get_choice(std::string_view key,
                                                     std::span<const std::string_view> names,
                                                     Need need) {
  auto found = lookup(key, need);
  if (!found) return std::nullopt;
  const auto& [v, line] = *found;
  const std::string path = path_of(key);
  std::string list;
  std::set<std::string, std::less<>> name_set;
  for (std::string_view n : names) {
    list += (list.empty() ? "" : ", ") + std::string(n);
    name_set.emplace(n);
  }
  if (!v.IsScalar()) {
    ctx_->error(here(line_of(v, line)), path, "expected one of " + list + ", got " + describe(v));
    return std::nullopt;
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == v.Scalar()) {
      ctx_->set_origin(path, here(line));
      return i;
    }
  }
  std::string msg = "'" + v.Scalar() + "' is not one of " + list;
  if (std::string near = closest_match(v.Scalar(), name_set); !near.empty()) {
    msg += " (did you mean '" + near + "'?)";
  }
  ctx_->error(here(line), path, msg);
  return std::nullopt;
}

SectionReader SectionReader::section(std::string_view key, Need need) {
  known_.emplace(key);
  const std::string path = path_of(key);
  if (const Entry* e = find(key)) {
    if (e->value.IsMap()) return SectionReader(e->value, path, file_, e->line, *ctx_);
    // An empty section (`map:` with nothing under it) is allowed: it sets nothing.
    if (!e->value.IsNull()) {
      ctx_->error(here(e->line), path, "expected a mapping, got " + describe(e->value));
    }
    return SectionReader(YAML::Node(), path, file_, e->line, *ctx_);
  }
  if (need == Need::kRequired) ctx_->note_required(path, here(key_line_));
  return SectionReader(YAML::Node(), path, file_, key_line_, *ctx_);
}

void SectionReader::finish() {
  if (finished_) return;
  finished_ = true;
  std::map<std::string, int, std::less<>> seen;  // key -> first line
  for (const Entry& e : entries_) {
    if (!e.key_node.IsScalar()) {
      ctx_->error(here(e.line), path_, "keys must be plain names, got " + describe(e.key_node));
      continue;
    }
    if (auto [it, fresh] = seen.emplace(e.key, e.line); !fresh) {
      ctx_->error(here(e.line), path_of(e.key),
                  "duplicate key (first given on line " + std::to_string(it->second) + ")");
      continue;
    }
    if (known_.count(e.key) != 0) continue;
    std::string msg = "unknown key";
    if (std::string near = closest_match(e.key, known_); !near.empty()) {
      msg += " (did you mean '" + near + "'?)";
    }
    ctx_->error(here(e.line), path_of(e.key), msg);
  }
}

// ---- suggestions ---------------------------------------------------------------------------

std::size_t edit_distance(std::string_view a, std::string_view b) {
  // Optimal string alignment distance, three rolling rows.
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::size_t> prev2(m + 1), prev(m + 1), cur(m + 1);
  for (std::size_t j = 0; j <= m; ++j) prev[j] = j;
  for (std::size_t i = 1; i <= n; ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= m; ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        cur[j] = std::min(cur[j], prev2[j - 2] + 1);
      }
    }
    std::swap(prev2, prev);
    std::swap(prev, cur);
  }
  return prev[m];
}

std::string closest_match(std::string_view word, const std::set<std::string, std::less<>>& known) {
  // Accept roughly one edit per three characters, at most three: close enough to be a typo,
  // far enough that unrelated short names are not suggested.
  const std::size_t limit = std::max<std::size_t>(1, std::min<std::size_t>(3, word.size() / 3));
  std::string best;
  std::size_t best_d = limit + 1;
  for (const std::string& k : known) {
    const std::size_t d = edit_distance(word, k);
    if (d < best_d) {
      best_d = d;
      best = k;
    }
  }
  return best;
}

}  // namespace storey::config
