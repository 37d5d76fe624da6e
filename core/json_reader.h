// Reading JSON documents that users give subflow (cameras.json, result reports, importer
// files): one mapping of every failure to "<file>: <field>: <what was expected>".
//
// ParseJson replaces nlohmann's exceptions, which name neither the file nor the field
// ("[json.exception.out_of_range.406] number overflow parsing '1e999'"), with a
// subflow::Error naming the file, the path of the value being read when parsing failed
// (JSON-pointer-like, "cameras[0].K[0][0]"), the line and column, and what was expected.
// While parsing it also refuses what nlohmann would accept silently but a reader cannot
// trust: numbers beyond double's range (nlohmann: an exception without the field),
// duplicate keys (nlohmann keeps the last), and nesting deeper than kMaxJsonDepth (whose
// recursive printing could exhaust the stack).
//
// JsonReader then reads fields with their expectation: Number (finite), Integer (in a
// range), String, Vector, Matrix, Required/Optional members and OnlyKeys; every failure
// names the file and the field. Values shown in messages are cut to kMaxShownJson
// characters, so an error stays one readable line whatever the document holds.
//
// A new JSON reader (an importer, the result reader) needs nothing else: parse with
// ReadJsonFile / ParseJson and read through a JsonReader.
#pragma once

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace subflow {

inline constexpr int kMaxJsonDepth = 64;
inline constexpr std::size_t kMaxShownJson = 80;

namespace json_detail {

// "line L, column C" of the 1-based byte offset `byte` (as nlohmann reports it).
inline std::string LineColumn(const std::string& text, std::size_t byte) {
  int line = 1, column = 1;
  for (std::size_t i = 0; i + 1 < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

// nlohmann's message without its "[json.exception.parse_error.101] parse error at line
// 1, column 2: " prefix (we give the position ourselves).
inline std::string Reason(const std::string& what) {
  std::string reason = what;
  const std::size_t bracket = reason.find("] ");
  if (reason.rfind("[json.exception.", 0) == 0 && bracket != std::string::npos)
    reason = reason.substr(bracket + 2);
  const std::size_t colon = reason.find(": ");
  if (reason.rfind("parse error", 0) == 0 && colon != std::string::npos)
    reason = reason.substr(colon + 2);
  return reason;
}

// Where the parser is: one entry per open object or array.
struct Level {
  bool is_array = false;
  std::string key;                // object: the latest key read
  std::set<std::string> keys;     // object: every key read so far
  std::size_t elements_done = 0;  // array: elements completed so far
};

inline std::string PathOf(const std::vector<Level>& stack) {
  std::string path;
  for (const Level& level : stack) {
    if (level.is_array)
      path += "[" + std::to_string(level.elements_done) + "]";
    else if (!level.key.empty())
      path += (path.empty() ? "" : ".") + level.key;
  }
  return path.empty() ? "(top level)" : path;
}

inline void ElementDone(std::vector<Level>* stack) {
  if (!stack->empty() && stack->back().is_array) ++stack->back().elements_done;
}

}  // namespace json_detail

// A value as shown in a message: compact JSON, cut to kMaxShownJson characters.
inline std::string ShowJson(const nlohmann::json& value) {
  std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (text.size() > kMaxShownJson) text = text.substr(0, kMaxShownJson - 3) + "...";
  return text;
}

// Parses `text`, the content of `source`; `expected` says what the document should be
// ("the dataset's cameras.json"). Throws subflow::Error as described in the file comment.
inline nlohmann::json ParseJson(const std::string& text, const std::string& source,
                                const std::string& expected) {
  using nlohmann::json;
  std::vector<json_detail::Level> stack;
  auto track = [&](int depth, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        if (stack.size() >= static_cast<std::size_t>(kMaxJsonDepth))
          ThrowError(source, json_detail::PathOf(stack),
                     "nesting deeper than " + std::to_string(kMaxJsonDepth) + " levels (expected " +
                         expected + ")");
        stack.push_back({event == json::parse_event_t::array_start, "", {}, 0});
        break;
      case json::parse_event_t::key: {
        const std::string key = parsed.get<std::string>();
        if (!stack.back().keys.insert(key).second) {
          stack.back().key = key;
          ThrowError(source, json_detail::PathOf(stack),
                     "duplicate key \"" + key + "\" (expected each key once per object)");
        }
        stack.back().key = key;
        break;
      }
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        stack.pop_back();
        json_detail::ElementDone(&stack);
        break;
      case json::parse_event_t::value:
        json_detail::ElementDone(&stack);
        break;
    }
    (void)depth;
    return true;
  };
  try {
    return json::parse(text, track);
  } catch (const json::parse_error& e) {
    ThrowError(source, json_detail::PathOf(stack),
               "invalid JSON at " + json_detail::LineColumn(text, e.byte) + ": " +
                   json_detail::Reason(e.what()) + " (expected " + expected + ")");
  } catch (const json::out_of_range& e) {
    // 406: a number whose magnitude exceeds double's range ("1e999").
    ThrowError(source, json_detail::PathOf(stack),
               json_detail::Reason(e.what()) +
                   " (expected a finite number, at most 1.8e308 in magnitude)");
  } catch (const json::exception& e) {
    ThrowError(source, json_detail::PathOf(stack),
               json_detail::Reason(e.what()) + " (expected " + expected + ")");
  }
}

// Reads and parses the file `path` (see ParseJson).
inline nlohmann::json ReadJsonFile(const std::string& path, const std::string& expected) {
  std::ifstream file(path, std::ios::binary);
  if (!file)
    ThrowError(path, "", std::string("cannot open: ") + std::strerror(errno) + " (expected " +
                             expected + ")");
  std::stringstream buffer;
  buffer << file.rdbuf();
  if (file.bad()) ThrowError(path, "", "read error (expected " + expected + ")");
  return ParseJson(buffer.str(), path, expected);
}

// Typed access to the fields of a parsed document; every failure names `source` and the
// field ("cameras[2] (\"cam02\").K[0][0]").
class JsonReader {
 public:
  explicit JsonReader(std::string source) : source_(std::move(source)) {}

  const std::string& source() const { return source_; }

  [[noreturn]] void Fail(const std::string& field, const std::string& problem) const {
    ThrowError(source_, field, problem);
  }

  // "where.key" (or "key" at the top level).
  static std::string Join(const std::string& where, const std::string& key) {
    return where.empty() ? key : where + "." + key;
  }

  // object[key]; throws when `object` is not an object or lacks `key`.
  const nlohmann::json& Required(const nlohmann::json& object, const std::string& key,
                                 const std::string& where) const {
    RequireObject(object, where);
    const auto it = object.find(key);
    if (it == object.end()) Fail(Join(where, key), "missing required field \"" + key + "\"");
    return *it;
  }

  // object[key] or nullptr when absent.
  const nlohmann::json* Optional(const nlohmann::json& object, const std::string& key,
                                 const std::string& where) const {
    RequireObject(object, where);
    const auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
  }

  void RequireObject(const nlohmann::json& value, const std::string& field) const {
    if (!value.is_object())
      Fail(field.empty() ? "(top level)" : field,
           std::string("expected a JSON object, got ") + value.type_name() + " " + ShowJson(value));
  }

  // Every key of `object` is one of `allowed`.
  void OnlyKeys(const nlohmann::json& object, const std::set<std::string>& allowed,
                const std::string& where) const {
    RequireObject(object, where);
    for (auto it = object.begin(); it != object.end(); ++it)
      if (!allowed.count(it.key())) {
        std::string list;
        for (const auto& key : allowed) list += (list.empty() ? "" : ", ") + key;
        Fail(Join(where, it.key()), "unknown field (expected one of: " + list + ")");
      }
  }

  // A finite number.
  double Number(const nlohmann::json& value, const std::string& field) const {
    if (!value.is_number())
      Fail(field, std::string("expected a number, got ") + value.type_name() + " " + ShowJson(value));
    const double x = value.get<double>();
    if (!std::isfinite(x)) Fail(field, "expected a finite number, got " + ShowJson(value));
    return x;
  }

  // An integer in [min, max] (written without fraction or exponent, as JSON integers are).
  long long Integer(const nlohmann::json& value, const std::string& field, long long min,
                    long long max) const {
    const std::string range = "[" + std::to_string(min) + ", " + std::to_string(max) + "]";
    bool in_range = false;
    long long x = 0;
    if (value.is_number_unsigned()) {
      const auto u = value.get<unsigned long long>();
      in_range = u <= static_cast<unsigned long long>(std::numeric_limits<long long>::max());
      x = in_range ? static_cast<long long>(u) : 0;
    } else if (value.is_number_integer()) {
      x = value.get<long long>();
      in_range = true;
    } else {
      Fail(field, "expected an integer in " + range + ", got " + ShowJson(value));
    }
    if (!in_range || x < min || x > max)
      Fail(field, "expected an integer in " + range + ", got " + ShowJson(value));
    return x;
  }

  std::string String(const nlohmann::json& value, const std::string& field) const {
    if (!value.is_string())
      Fail(field, std::string("expected a string, got ") + value.type_name() + " " + ShowJson(value));
    return value.get<std::string>();
  }

  // An array of finite numbers, of `size` elements (any size when size < 0).
  std::vector<double> Numbers(const nlohmann::json& value, int size, const std::string& field) const {
    if (!value.is_array() || (size >= 0 && value.size() != static_cast<std::size_t>(size)))
      Fail(field, "expected an array of " + (size >= 0 ? std::to_string(size) + " " : std::string()) +
                      "numbers, got " + ShowJson(value));
    std::vector<double> out;
    out.reserve(value.size());
    for (std::size_t i = 0; i < value.size(); ++i)
      out.push_back(Number(value[i], field + "[" + std::to_string(i) + "]"));
    return out;
  }

  // rows × cols numbers written as `rows` arrays of `cols` numbers, row-major.
  std::vector<double> Matrix(const nlohmann::json& value, int rows, int cols,
                             const std::string& field) const {
    const std::string shape = std::to_string(rows) + "×" + std::to_string(cols) + " matrix as " +
                              std::to_string(rows) + " rows of " + std::to_string(cols) + " numbers";
    if (!value.is_array() || value.size() != static_cast<std::size_t>(rows))
      Fail(field, "expected a " + shape + ", got " + ShowJson(value));
    std::vector<double> out;
    for (int r = 0; r < rows; ++r) {
      const std::vector<double> row = Numbers(value[r], cols, field + "[" + std::to_string(r) + "]");
      out.insert(out.end(), row.begin(), row.end());
    }
    return out;
  }

 private:
  std::string source_;
};

}  // namespace subflow
