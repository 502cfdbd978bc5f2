#pragma once
// A simulated device's object dictionary built from its EDS (CiA 306, INI
// syntax, read with libinih): every object the file lists, with its size
// (DataType), access (AccessType), PDO mapping, value range (LowLimit,
// HighLimit) and power-on value (DefaultValue, $NODEID as the device's own
// node id). So the EDS shipped for a device and the device that plays it
// cannot disagree. The reader is this folder's own, not the master's
// (drivers/can/eds.h): a misreading of CiA 306 on one side shows as a
// failure on the other.

#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "virtual-robot/object_dictionary.h"

namespace cdpr::virtual_robot {

// An EDS as a device holds it: its file name (for messages) and text.
struct DeviceEds {
  std::string name;
  std::string text;
};

// Power-on values the device keeps in its non-volatile memory (CiA 301
// 0x1010 "store parameters"): it comes up (and resets) with these instead of
// the EDS's DefaultValue. Key: index << 8 | subindex.
using StoredParameters = std::map<std::uint32_t, std::uint32_t>;
constexpr std::uint32_t object_key(std::uint16_t index, std::uint8_t subindex) {
  return static_cast<std::uint32_t>(index) << 8 | subindex;
}

// Adds the objects `eds` lists to `od`; empty on success, else why not
// ("<name>:<line>: ..." or "<name> [6081] DataType=0x0009: ...").
std::string add_objects_from_eds(const DeviceEds& eds, int node_id, const StoredParameters& stored,
                                 ObjectDictionary& od);

// The dictionary `eds` describes, whose objects a profile then checks with
// `missing` ("" or "no object 0x6041:00 ..."); `error` (naming the file)
// empty when it fits.
ObjectDictionary dictionary_from_eds(const DeviceEds& eds, int node_id, const StoredParameters& stored,
                                     const std::function<std::string(const ObjectDictionary&)>& missing,
                                     std::string& error);
// `od`, or an abort naming `device` and `error` when there is one: for a
// program's own EDS, which it checks first when it comes from outside.
ObjectDictionary dictionary_or_abort(const char* device, ObjectDictionary od, const std::string& error);

// The file at `path`; empty `text` and `error` set when it cannot be read.
DeviceEds read_device_eds(const std::string& path, std::string& error);

// The virtual devices' EDS files of systemd/eds, built into the program
// ("cdpr-virtual-drive.eds", ...); aborts on a name not among them.
const DeviceEds& shipped_eds(const std::string& file_name);

}  // namespace cdpr::virtual_robot
