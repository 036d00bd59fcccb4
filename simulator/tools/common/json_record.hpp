// SPDX-License-Identifier: GPL-2.0-or-later
// JsonRecord: a small JSON record another program wrote (sim_manager's manager.json, a watcher's session.json),
// parsed and its keys read strictly, each error naming the file and the key ("DIR/manager.json: key 'uid':
// expected a string"). `Error` is the exception its reader's callers catch. Header-only.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

namespace rfbsim::tools {

template <class Error>
class JsonRecord {
 public:
  using json = nlohmann::json;

  /// Parses `bytes` (the content of `file`); throws Error when it is not JSON or not an object.
  JsonRecord(const std::string& bytes, std::filesystem::path file) : file_(std::move(file)) {
    try {
      doc_ = json::parse(bytes);
    } catch (const json::exception& e) {
      fail(std::string("not JSON (") + e.what() + ")");
    }
    if (!doc_.is_object()) fail("expected a JSON object");
  }

  [[nodiscard]] const json& doc() const { return doc_; }

  /// Throws Error("FILE: what").
  [[noreturn]] void fail(const std::string& what) const { throw Error(file_.string() + ": " + what); }

  /// The value under `key` of `object` when it is there and not null.
  static const json* present(const json& object, const char* key) {
    const auto it = object.find(key);
    return it == object.end() || it->is_null() ? nullptr : &*it;
  }

  /// The string under `key` of `object` (the document by default); absent or null is none, or an error when
  /// `required`. `where` prefixes the key in errors ("replay_of." for a nested object).
  std::optional<std::string> text(const char* key, bool required, const json* object = nullptr,
                                  const std::string& where = "") const {
    const json* value = present(object ? *object : doc_, key);
    if (!value) {
      if (required) fail("key '" + where + key + "': missing");
      return std::nullopt;
    }
    if (!value->is_string()) fail("key '" + where + key + "': expected a string");
    return value->get<std::string>();
  }

  /// The integer under `key` of the document (a session id); absent or null is none. `expected` words the
  /// error for anything else ("an integer").
  std::optional<std::int64_t> integer(const char* key, const std::string& expected) const {
    const json* value = present(doc_, key);
    if (!value) return std::nullopt;
    if (!value->is_number_integer()) fail(std::string("key '") + key + "': expected " + expected);
    return value->get<std::int64_t>();
  }

 private:
  std::filesystem::path file_;
  json doc_;
};

}  // namespace rfbsim::tools
