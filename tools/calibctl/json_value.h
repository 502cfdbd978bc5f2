#pragma once
// A read-only view of the control socket's one-line JSON responses
// (src/control/control_response.h), parsed by nlohmann-json. Only
// json_value.cc includes the full nlohmann header.
//
// Nothing here throws on what the daemon sends: parsing refuses malformed
// text, and the accessors return a default for a missing member or the wrong
// kind, so a response from a newer daemon with a changed field shows a
// blank, never crashes calibctl.

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace cdpr::calibctl {

class JsonValue {
 public:
  JsonValue() = default;  // null

  bool is_null() const;
  bool boolean() const;  // false unless true
  double number(double fallback = 0.0) const;
  int integer() const;  // number() truncated, clamped to int's range
  std::string string() const;
  std::vector<JsonValue> array() const;
  // Member `key` of an object; a null value when absent.
  JsonValue operator[](std::string_view key) const;

  // One JSON text (surrounding white space allowed).
  static std::optional<JsonValue> parse(std::string_view text, std::string* error = nullptr);

 private:
  JsonValue(std::shared_ptr<const nlohmann::json> document, const nlohmann::json* node)
      : document_(std::move(document)), node_(node) {}

  std::shared_ptr<const nlohmann::json> document_;  // keeps node_ alive
  const nlohmann::json* node_ = nullptr;             // inside *document_; nullptr: null
};

}  // namespace cdpr::calibctl
