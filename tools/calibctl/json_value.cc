#include "calibctl/json_value.h"

#include <algorithm>
#include <limits>

#include <nlohmann/json.hpp>

namespace cdpr::calibctl {

bool JsonValue::is_null() const { return node_ == nullptr || node_->is_null(); }

bool JsonValue::boolean() const { return node_ != nullptr && node_->is_boolean() && node_->get<bool>(); }

double JsonValue::number(double fallback) const {
  return node_ != nullptr && node_->is_number() ? node_->get<double>() : fallback;
}

int JsonValue::integer() const {
  constexpr double kLowest = std::numeric_limits<int>::lowest();
  constexpr double kMax = std::numeric_limits<int>::max();
  return static_cast<int>(std::clamp(number(), kLowest, kMax));
}

std::string JsonValue::string() const {
  return node_ != nullptr && node_->is_string() ? node_->get<std::string>() : std::string();
}

std::vector<JsonValue> JsonValue::array() const {
  std::vector<JsonValue> elements;
  if (node_ == nullptr || !node_->is_array()) return elements;
  elements.reserve(node_->size());
  for (const nlohmann::json& element : *node_) elements.push_back(JsonValue(document_, &element));
  return elements;
}

JsonValue JsonValue::operator[](std::string_view key) const {
  if (node_ == nullptr || !node_->is_object()) return {};
  const auto member = node_->find(std::string(key));
  return member == node_->end() ? JsonValue() : JsonValue(document_, &*member);
}

std::optional<JsonValue> JsonValue::parse(std::string_view text, std::string* error) {
  auto document = std::make_shared<nlohmann::json>(nlohmann::json::parse(text, nullptr, false));
  if (document->is_discarded()) {
    if (error) *error = "not a valid JSON text";
    return std::nullopt;
  }
  const nlohmann::json* root = document.get();
  return JsonValue(std::move(document), root);
}

}  // namespace cdpr::calibctl
