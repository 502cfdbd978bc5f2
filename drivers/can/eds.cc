#include "drivers/can/eds.h"

#include <ini.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>

namespace cdpr::drivers::can {
namespace {

constexpr std::uint32_t kCobIdNoRtr = 0x40000000u;

std::string lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// "1800" -> object 0x1800 sub 0 (a VAR), "1800sub2" -> sub 2; nullopt for
// other sections (DeviceInfo, FileInfo, lists).
std::optional<std::uint32_t> object_key(const std::string& section) {
  const std::string s = lower(section);
  if (s.size() < 4 || !std::all_of(s.begin(), s.begin() + 4, [](char c) { return std::isxdigit(c) != 0; })) {
    return std::nullopt;
  }
  const auto index = static_cast<std::uint32_t>(std::strtoul(s.substr(0, 4).c_str(), nullptr, 16));
  if (s.size() == 4) return index << 8;
  if (s.compare(4, 3, "sub") != 0 || s.size() == 7 || s.size() > 9) return std::nullopt;
  char* end = nullptr;
  const unsigned long sub = std::strtoul(s.c_str() + 7, &end, 16);
  if (*end != '\0' || sub > 0xFF) return std::nullopt;
  return index << 8 | static_cast<std::uint32_t>(sub);
}

// CiA 306 numbers: decimal, 0x hex, 0 octal, optionally with $NODEID
// added ("$NODEID+0x180", "0x180+$NODEID"), which is taken as 0 here.
std::optional<std::int64_t> number(std::string text) {
  text = lower(text);
  for (const char* node : {"$nodeid+", "+$nodeid", "$nodeid"}) {
    if (const std::size_t at = text.find(node); at != std::string::npos) text.erase(at, std::string(node).size());
  }
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.pop_back();
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 0);
  if (*end != '\0') return std::nullopt;
  return value;
}

std::string hex(std::uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof(text), "0x%X", static_cast<unsigned>(value));
  return text;
}

std::string key_text(const EdsEntry& e, const char* key, std::optional<std::int64_t> value) {
  return "[" + e.section + "] " + key + "=" + (value ? std::to_string(*value) : std::string("?"));
}

}  // namespace

int eds_handler(void* user, const char* section, const char* key, const char* value) {
  auto* eds = static_cast<Eds*>(user);
  const std::optional<std::uint32_t> object = object_key(section);
  if (!object) return 1;  // DeviceInfo, FileInfo, object lists: not needed
  EdsEntry& e = eds->entries_[*object];
  e.section = section;
  const std::string k = lower(key);
  if (k == "accesstype") {
    e.access = lower(value);
  } else if (k == "datatype") {
    const std::optional<std::int64_t> type = number(value);
    e.is_signed = type && *type >= 2 && *type <= 4;
  } else if (k == "lowlimit" || k == "highlimit" || k == "defaultvalue") {
    std::optional<std::int64_t> v = number(value);
    if (!v && *value != '\0') {
      eds->error_ = std::string("[") + section + "] " + key + "=" + value + ": not a number";
      return 0;
    }
    (k == "lowlimit" ? e.low : k == "highlimit" ? e.high : e.default_value) = v;
  } else if (k == "pdomapping") {
    e.pdo_mapping = number(value).value_or(0) != 0;
  }
  return 1;
}

std::optional<Eds> Eds::load(const std::string& path, std::string& error) {
  Eds eds;
  eds.name_ = path;
  const int result = ini_parse(path.c_str(), eds_handler, &eds);
  return finish(std::move(eds), result, error);
}

std::optional<Eds> Eds::parse(const std::string& text, const std::string& name, std::string& error) {
  Eds eds;
  eds.name_ = name;
  const int result = ini_parse_string(text.c_str(), eds_handler, &eds);
  return finish(std::move(eds), result, error);
}

std::optional<Eds> Eds::finish(Eds eds, int result, std::string& error) {
  if (result < 0) {
    error = eds.name_ + ": cannot read the EDS file";
    return std::nullopt;
  }
  if (result > 0) {
    error = eds.name_ + ":" + std::to_string(result) + ": " + (eds.error_.empty() ? "not INI syntax" : eds.error_);
    return std::nullopt;
  }
  // An ARRAY/RECORD's own section ("1800") describes no value: only its subs do.
  for (auto it = eds.entries_.begin(); it != eds.entries_.end();) {
    const bool record = (it->first & 0xFF) == 0 && it->second.access.empty();
    it = record ? eds.entries_.erase(it) : std::next(it);
  }
  if (eds.entries_.empty()) {
    error = eds.name_ + ": no objects: not an EDS file";
    return std::nullopt;
  }
  return eds;
}

const EdsEntry* Eds::find(std::uint16_t index, std::uint8_t subindex) const {
  const auto it = entries_.find(static_cast<std::uint32_t>(index) << 8 | subindex);
  return it == entries_.end() ? nullptr : &it->second;
}

bool Eds::has_index(std::uint16_t index) const {
  const auto it = entries_.lower_bound(static_cast<std::uint32_t>(index) << 8);
  return it != entries_.end() && (it->first >> 8) == index;
}

int Eds::rpdo_count() const {
  int n = 0;
  while (n < 512 && find(static_cast<std::uint16_t>(0x1400 + n), 1) != nullptr) ++n;
  return n;
}

int Eds::tpdo_count() const {
  int n = 0;
  while (n < 512 && find(static_cast<std::uint16_t>(0x1800 + n), 1) != nullptr) ++n;
  return n;
}

std::string fit_to_eds(const Eds& eds, std::vector<SdoStep>& steps) {
  std::vector<SdoStep> fitted;
  fitted.reserve(steps.size());
  for (SdoStep step : steps) {
    const EdsEntry* e = eds.find(step.index, step.subindex);
    char object[32];
    std::snprintf(object, sizeof(object), "0x%04X:0x%02X", step.index, step.subindex);
    if (e == nullptr) {
      if (step.optional) continue;  // the device does not have it: nothing to do there
      return eds.name() + ": no object " + object + " (" + step.what + "), which the daemon needs";
    }
    const bool writes = step.kind == SdoStep::Kind::kWrite || step.kind == SdoStep::Kind::kWriteVerify;
    if (writes && !e->writable()) {
      return eds.name() + " [" + e->section + "] AccessType=" + e->access + ": " + step.what + " (" + object +
             ") is written by the daemon";
    }
    if (!writes && !e->readable()) {
      return eds.name() + " [" + e->section + "] AccessType=" + e->access + ": " + step.what + " (" + object +
             ") is read by the daemon";
    }
    if (!writes) {
      fitted.push_back(step);
      continue;
    }
    const bool cob_id = (step.compare_mask & kCobIdNoRtr) == 0;
    if (cob_id && e->default_value && (*e->default_value & kCobIdNoRtr) != 0) step.value |= kCobIdNoRtr;
    const auto as_number = [&](std::uint32_t raw) -> std::int64_t {
      if (!e->is_signed) return raw;
      if (step.size == 1) return static_cast<std::int8_t>(raw);
      if (step.size == 2) return static_cast<std::int16_t>(raw);
      return static_cast<std::int32_t>(raw);
    };
    const auto in_range = [&](std::uint32_t raw) {
      const std::int64_t v = as_number(raw);
      return (!e->low || v >= *e->low) && (!e->high || v <= *e->high);
    };
    if (!in_range(step.value)) {
      if (step.has_fallback && in_range(step.fallback)) {
        step.value = step.fallback;  // 254 where the device's range stops short of 255
        step.has_fallback = false;
      } else {
        const bool low = e->low && as_number(step.value) < *e->low;
        return eds.name() + " " + key_text(*e, low ? "LowLimit" : "HighLimit", low ? e->low : e->high) + ": " +
               step.what + " (" + object + ") " + std::to_string(as_number(step.value)) + " (" + hex(step.value) +
               ") is out of the device's range";
      }
    }
    fitted.push_back(step);
  }
  steps = std::move(fitted);
  return {};
}

}  // namespace cdpr::drivers::can
