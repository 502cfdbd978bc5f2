#include "src/control/protocol_answer.h"

#include <nlohmann/json.hpp>

namespace cdpr::control {
namespace {

// Members keep their order: clients and tests compare whole lines.
using Json = nlohmann::ordered_json;

std::string answer(bool ok, const char* key, std::string_view text) {
  Json json;
  json["ok"] = ok;
  json[key] = std::string(text);
  return json.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n";
}

}  // namespace

std::string format_error_response(std::string_view reason) { return answer(false, "error", reason); }

std::string format_ok_response(std::string_view message) { return answer(true, "message", message); }

}  // namespace cdpr::control
