// A small JSON reader and string escaper for the evaluation's inputs (each run's metrics.json,
// written by tools/sim/metrics.cpp) and outputs (results.json). Not a general library: numbers
// are doubles, objects keep their key order, the whole document is held in memory.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace storey::tools::eval {

class JsonValue {
 public:
  enum class Kind { null, boolean, number, string, array, object };
  JsonValue() = default;  // null

  Kind kind() const { return kind_; }
  bool is_number() const { return kind_ == Kind::number; }
  bool is_bool() const { return kind_ == Kind::boolean; }
  bool is_string() const { return kind_ == Kind::string; }
  bool is_array() const { return kind_ == Kind::array; }
  bool is_object() const { return kind_ == Kind::object; }
  double number() const { return number_; }
  bool boolean() const { return boolean_; }
  const std::string& string() const { return string_; }
  const std::vector<JsonValue>& array() const { return array_; }
  // nullptr when this is not an object or has no such key.
  const JsonValue* find(const std::string& key) const;

  static JsonValue make_null() { return JsonValue(Kind::null); }
  static JsonValue make_bool(bool b);
  static JsonValue make_number(double d);
  static JsonValue make_string(std::string s);
  static JsonValue make_array(std::vector<JsonValue> a);
  static JsonValue make_object(std::vector<std::pair<std::string, JsonValue>> members);

 private:
  explicit JsonValue(Kind k) : kind_(k) {}
  Kind kind_ = Kind::null;
  bool boolean_ = false;
  double number_ = 0.0;
  std::string string_;
  std::vector<JsonValue> array_;
  std::vector<std::pair<std::string, JsonValue>> members_;
};

// Parses a whole document (trailing whitespace only). On failure returns false and sets *error to
// "byte N: what" (a truncated file reads as "unexpected end").
bool parse_json(std::string_view text, JsonValue& out, std::string* error);

// "..." with quotes, backslashes and control characters escaped.
std::string json_quote(std::string_view s);
// Shortest round-trippable-enough number text ("%.6g"); NaN/inf become null.
std::string json_number(double d);

}  // namespace storey::tools::eval
