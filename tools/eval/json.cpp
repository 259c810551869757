#include "tools/eval/json.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace storey::tools::eval {

const JsonValue* JsonValue::find(const std::string& key) const {
  if (kind_ != Kind::object) return nullptr;
  for (const auto& [k, v] : members_)
    if (k == key) return &v;
  return nullptr;
}

JsonValue JsonValue::make_bool(bool b) {
  JsonValue v(Kind::boolean);
  v.boolean_ = b;
  return v;
}
JsonValue JsonValue::make_number(double d) {
  JsonValue v(Kind::number);
  v.number_ = d;
  return v;
}
JsonValue JsonValue::make_string(std::string s) {
  JsonValue v(Kind::string);
  v.string_ = std::move(s);
  return v;
}
JsonValue JsonValue::make_array(std::vector<JsonValue> a) {
  JsonValue v(Kind::array);
  v.array_ = std::move(a);
  return v;
}
JsonValue JsonValue::make_object(std::vector<std::pair<std::string, JsonValue>> m) {
  JsonValue v(Kind::object);
  v.members_ = std::move(m);
  return v;
}

namespace {

// Recursive descent; depth-bounded so a hostile file cannot overflow the stack.
class Parser {
 public:
  explicit Parser(std::string_view t) : t_(t) {}

  bool document(JsonValue& out, std::string* error) {
    bool ok = value(out, 0);
    skip_ws();
    if (ok && i_ != t_.size()) ok = fail("trailing characters");
    if (!ok) {
      if (error) *error = "byte " + std::to_string(i_) + ": " + err_;
      return false;
    }
    return true;
  }

 private:
  bool fail(const char* what) {
    if (err_.empty()) err_ = what;
    return false;
  }
  void skip_ws() {
    while (i_ < t_.size() && (t_[i_] == ' ' || t_[i_] == '\n' || t_[i_] == '\r' || t_[i_] == '\t'))
      ++i_;
  }
  bool literal(std::string_view word) {
    if (t_.substr(i_, word.size()) != word) return fail("bad literal");
    i_ += word.size();
    return true;
  }
  bool value(JsonValue& out, int depth) {
    if (depth > 64) return fail("nesting deeper than 64");
    skip_ws();
    if (i_ >= t_.size()) return fail("unexpected end");
    const char c = t_[i_];
    if (c == '{') return object(out, depth);
    if (c == '[') return array(out, depth);
    if (c == '"') {
      std::string s;
      if (!string(s)) return false;
      out = JsonValue::make_string(std::move(s));
      return true;
    }
    if (c == 't') return literal("true") && (out = JsonValue::make_bool(true), true);
    if (c == 'f') return literal("false") && (out = JsonValue::make_bool(false), true);
    if (c == 'n') return literal("null") && (out = JsonValue::make_null(), true);
    return number(out);
  }
  bool number(JsonValue& out) {
    const size_t start = i_;
    while (i_ < t_.size() && (std::isdigit(static_cast<unsigned char>(t_[i_])) || t_[i_] == '-' ||
                              t_[i_] == '+' || t_[i_] == '.' || t_[i_] == 'e' || t_[i_] == 'E'))
      ++i_;
    if (i_ == start) return fail("unexpected character");
    const std::string s(t_.substr(start, i_ - start));
    char* end = nullptr;
    const double d = std::strtod(s.c_str(), &end);
    if (!end || *end != '\0' || !std::isfinite(d)) return fail("bad number");
    out = JsonValue::make_number(d);
    return true;
  }
  bool string(std::string& s) {
    ++i_;  // opening quote
    while (i_ < t_.size() && t_[i_] != '"') {
      char c = t_[i_++];
      if (static_cast<unsigned char>(c) < 0x20) return fail("control character in string");
      if (c == '\\') {
        if (i_ >= t_.size()) return fail("unexpected end");
        const char e = t_[i_++];
        switch (e) {
          case 'n':
            c = '\n';
            break;
          case 't':
            c = '\t';
            break;
          case 'r':
            c = '\r';
            break;
          case 'b':
            c = '\b';
            break;
          case 'f':
            c = '\f';
            break;
          case '"':
          case '\\':
          case '/':
            c = e;
            break;
          case 'u': {
            if (i_ + 4 > t_.size()) return fail("unexpected end");
            const unsigned long cp =
                std::strtoul(std::string(t_.substr(i_, 4)).c_str(), nullptr, 16);
            i_ += 4;
            // UTF-8 of the basic plane (surrogate pairs are not expected in our files).
            if (cp < 0x80) {
              c = char(cp);
            } else if (cp < 0x800) {
              s += char(0xC0 | (cp >> 6));
              c = char(0x80 | (cp & 0x3F));
            } else {
              s += char(0xE0 | (cp >> 12));
              s += char(0x80 | ((cp >> 6) & 0x3F));
              c = char(0x80 | (cp & 0x3F));
            }
            break;
          }
          default:
            return fail("bad escape");
        }
      }
      s += c;
    }
    if (i_ >= t_.size()) return fail("unexpected end");
    ++i_;  // closing quote
    return true;
  }
  bool array(JsonValue& out, int depth) {
    ++i_;
    std::vector<JsonValue> items;
    skip_ws();
    if (i_ < t_.size() && t_[i_] == ']') {
      ++i_;
      out = JsonValue::make_array({});
      return true;
    }
    for (;;) {
      JsonValue v;
      if (!value(v, depth + 1)) return false;
      items.push_back(std::move(v));
      skip_ws();
      if (i_ >= t_.size()) return fail("unexpected end");
      if (t_[i_] == ',') {
        ++i_;
        continue;
      }
      if (t_[i_] != ']') return fail("expected ',' or ']'");
      ++i_;
      out = JsonValue::make_array(std::move(items));
      return true;
    }
  }
  bool object(JsonValue& out, int depth) {
    ++i_;
    std::vector<std::pair<std::string, JsonValue>> members;
    skip_ws();
    if (i_ < t_.size() && t_[i_] == '}') {
      ++i_;
      out = JsonValue::make_object({});
      return true;
    }
    for (;;) {
      skip_ws();
      if (i_ >= t_.size()) return fail("unexpected end");
      if (t_[i_] != '"') return fail("expected a key");
      std::string key;
      if (!string(key)) return false;
      skip_ws();
      if (i_ >= t_.size()) return fail("unexpected end");
      if (t_[i_] != ':') return fail("expected ':'");
      ++i_;
      JsonValue v;
      if (!value(v, depth + 1)) return false;
      members.emplace_back(std::move(key), std::move(v));
      skip_ws();
      if (i_ >= t_.size()) return fail("unexpected end");
      if (t_[i_] == ',') {
        ++i_;
        continue;
      }
      if (t_[i_] != '}') return fail("expected ',' or '}'");
      ++i_;
      out = JsonValue::make_object(std::move(members));
      return true;
    }
  }

  std::string_view t_;
  size_t i_ = 0;
  std::string err_;
};

}  // namespace

bool parse_json(std::string_view text, JsonValue& out, std::string* error) {
  return Parser(text).document(out, error);
}

std::string json_quote(std::string_view s) {
  std::string r = "\"";
  for (const char c : s) {
    switch (c) {
      case '"':
        r += "\\\"";
        break;
      case '\\':
        r += "\\\\";
        break;
      case '\n':
        r += "\\n";
        break;
      case '\t':
        r += "\\t";
        break;
      case '\r':
        r += "\\r";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char b[8];
          std::snprintf(b, sizeof b, "\\u%04x", unsigned(c));
          r += b;
        } else {
          r += c;
        }
    }
  }
  return r + "\"";
}

std::string json_number(double d) {
  if (!std::isfinite(d)) return "null";
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", d);
  return b;
}

}  // namespace storey::tools::eval
