#include "virtual-robot/object_dictionary_eds.h"

#include <ini.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>

namespace cdpr::virtual_robot {
namespace {

struct Pending {
  std::string section;
  std::string data_type, access, default_value, low, high;
  bool mappable = false;
};

struct Reader {
  int node_id = 0;
  std::map<std::uint32_t, Pending> objects;
  std::string error;
};

std::string eds_lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// "6081" -> 0x608100, "1800sub2" -> 0x180002; nullopt for FileInfo, DeviceInfo, object lists.
std::optional<std::uint32_t> section_object(const std::string& section) {
  const std::string s = eds_lower(section);
  if (s.size() < 4 || !std::all_of(s.begin(), s.begin() + 4, [](char c) { return std::isxdigit(c) != 0; })) {
    return std::nullopt;
  }
  const auto index = static_cast<std::uint32_t>(std::stoul(s.substr(0, 4), nullptr, 16));
  if (s.size() == 4) return index << 8;
  if (s.compare(4, 3, "sub") != 0 || s.size() == 7 || s.size() > 9) return std::nullopt;
  char* end = nullptr;
  const unsigned long sub = std::strtoul(s.c_str() + 7, &end, 16);
  if (*end != '\0' || sub > 0xFF) return std::nullopt;
  return index << 8 | static_cast<std::uint32_t>(sub);
}

int on_key(void* user, const char* section, const char* key, const char* value) {
  auto* reader = static_cast<Reader*>(user);
  const std::optional<std::uint32_t> object = section_object(section);
  if (!object) return 1;
  Pending& p = reader->objects[*object];
  p.section = section;
  const std::string k = eds_lower(key);
  if (k == "datatype") p.data_type = value;
  if (k == "accesstype") p.access = eds_lower(value);
  if (k == "defaultvalue") p.default_value = value;
  if (k == "lowlimit") p.low = value;
  if (k == "highlimit") p.high = value;
  if (k == "pdomapping") p.mappable = std::strtol(value, nullptr, 0) != 0;
  return 1;
}

// A CiA 306 number: decimal, 0x hex or 0 octal, "$NODEID" added where it appears.
std::optional<std::int64_t> eds_number(std::string text, int node_id) {
  text = eds_lower(text);
  std::int64_t add = 0;
  for (const std::string node : {"$nodeid+", "+$nodeid", "$nodeid"}) {
    if (const std::size_t at = text.find(node); at != std::string::npos) {
      text.erase(at, node.size());
      add = node_id;
      break;
    }
  }
  if (text.empty()) return add;
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 0);
  if (*end != '\0') return std::nullopt;
  return value + add;
}

struct DataType {
  std::uint8_t size = 0;
  bool is_signed = false;
};

// CiA 301 basic data types of at most 4 bytes (all this device's SDO server transfers).
std::optional<DataType> eds_data_type(const std::string& text) {
  switch (eds_number(text, 0).value_or(-1)) {
    case 0x0001: return DataType{1, false};  // BOOLEAN
    case 0x0002: return DataType{1, true};   // INTEGER8
    case 0x0003: return DataType{2, true};   // INTEGER16
    case 0x0004: return DataType{4, true};   // INTEGER32
    case 0x0005: return DataType{1, false};  // UNSIGNED8
    case 0x0006: return DataType{2, false};  // UNSIGNED16
    case 0x0007: return DataType{4, false};  // UNSIGNED32
    default: return std::nullopt;
  }
}

}  // namespace

std::string add_objects_from_eds(const DeviceEds& eds, int node_id, const StoredParameters& stored,
                                 ObjectDictionary& od) {
  Reader reader;
  reader.node_id = node_id;
  const int line = ini_parse_string(eds.text.c_str(), on_key, &reader);
  if (line != 0) return eds.name + ":" + std::to_string(line) + ": not INI syntax";
  int added = 0;
  for (const auto& [key, p] : reader.objects) {
    if ((key & 0xFF) == 0 && p.access.empty()) continue;  // an ARRAY's or RECORD's own section
    const std::string where = eds.name + " [" + p.section + "] ";
    const std::optional<DataType> type = eds_data_type(p.data_type);
    if (!type) return where + "DataType=" + p.data_type + ": not a type of at most 4 bytes this device plays";
    Access access = Access::kReadWrite;
    if (p.access == "ro" || p.access == "const") {
      access = Access::kReadOnly;
    } else if (p.access != "rw" && p.access != "wo" && p.access != "rwr" && p.access != "rww") {
      return where + "AccessType=" + p.access + ": not a CiA 306 access type";
    }
    const std::optional<std::int64_t> value = eds_number(p.default_value, node_id);
    if (!value) return where + "DefaultValue=" + p.default_value + ": not a number";
    const std::optional<std::int64_t> low = p.low.empty() ? std::nullopt : eds_number(p.low, node_id);
    const std::optional<std::int64_t> high = p.high.empty() ? std::nullopt : eds_number(p.high, node_id);
    if ((!p.low.empty() && !low) || (!p.high.empty() && !high)) return where + "LowLimit/HighLimit: not a number";
    const auto index = static_cast<std::uint16_t>(key >> 8);
    const auto subindex = static_cast<std::uint8_t>(key & 0xFF);
    const auto it = stored.find(key);
    od.add(index, subindex, type->size, access, p.mappable,
           it != stored.end() ? it->second : static_cast<std::uint32_t>(*value));
    od.set_limits(index, subindex, type->is_signed, low, high);
    ++added;
  }
  if (added == 0) return eds.name + ": no objects: not an EDS file";
  for (const auto& [key, value] : stored) {
    (void)value;
    if (od.find(static_cast<std::uint16_t>(key >> 8), static_cast<std::uint8_t>(key & 0xFF)) == nullptr) {
      return eds.name + ": a stored parameter for an object it does not list";
    }
  }
  return {};
}

ObjectDictionary dictionary_from_eds(const DeviceEds& eds, int node_id, const StoredParameters& stored,
                                     const std::function<std::string(const ObjectDictionary&)>& missing,
                                     std::string& error) {
  ObjectDictionary od;
  error = add_objects_from_eds(eds, node_id, stored, od);
  if (!error.empty()) return od;
  error = missing(od);
  if (!error.empty()) error = eds.name + ": " + error;
  return od;
}

ObjectDictionary dictionary_or_abort(const char* device, ObjectDictionary od, const std::string& error) {
  if (error.empty()) return od;
  std::fprintf(stderr, "%s: %s\n", device, error.c_str());
  std::abort();
}

DeviceEds read_device_eds(const std::string& path, std::string& error) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in || text.str().empty()) {
    error = path + ": cannot read the EDS file";
    return {};
  }
  return DeviceEds{path, text.str()};
}

}  // namespace cdpr::virtual_robot
