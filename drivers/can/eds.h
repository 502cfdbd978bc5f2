#pragma once
// A CANopen device's electronic data sheet (EDS, or a DCF: CiA 306, INI
// syntax, parsed with libinih): which objects the device has, their access
// type, range and default, and its PDO count. The master fits its
// configuration steps to it (fit_to_eds): objects the device lacks are
// left out where optional and refused where needed, values outside the
// object's range or written to a read-only object are refused with the
// file, section and key; the transmission type falls back to 254 where the
// range excludes 255; COB-ID bit 30 is written as the device's default has
// it. Loaded once at start; lookups allocate nothing.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "drivers/can/node_configurator.h"

namespace cdpr::drivers::can {

struct EdsEntry {
  std::string section;   // as the file names it: "1800sub2", "6081"
  std::string access;    // AccessType, lower case: ro, wo, rw, rwr, rww, const
  bool is_signed = false;  // DataType INTEGER8/16/32
  std::optional<std::int64_t> low, high;  // LowLimit, HighLimit
  std::optional<std::int64_t> default_value;  // DefaultValue, $NODEID taken as 0
  bool pdo_mapping = false;
  bool readable() const { return access != "wo"; }
  bool writable() const { return access == "rw" || access == "wo" || access == "rwr" || access == "rww"; }
};

class Eds {
 public:
  // The file at `path`; nullopt with `error` ("<path>:<line>: why") when it
  // cannot be read or is not an EDS.
  static std::optional<Eds> load(const std::string& path, std::string& error);
  // The same from text (`name` for messages).
  static std::optional<Eds> parse(const std::string& text, const std::string& name, std::string& error);

  const std::string& name() const { return name_; }
  const EdsEntry* find(std::uint16_t index, std::uint8_t subindex) const;
  bool has_index(std::uint16_t index) const;
  // RPDOs / TPDOs the device has (communication objects 0x1400.. / 0x1800.. present).
  int rpdo_count() const;
  int tpdo_count() const;

 private:
  friend int eds_handler(void* user, const char* section, const char* key, const char* value);
  static std::optional<Eds> finish(Eds eds, int result, std::string& error);
  std::string name_;
  std::map<std::uint32_t, EdsEntry> entries_;  // index << 8 | subindex
  std::string error_;
};

// Fits `steps` to the device `eds` describes (see above). Empty when they
// fit, else why not: "epos4.eds [6065] AccessType=ro: following error
// window is written by the daemon".
std::string fit_to_eds(const Eds& eds, std::vector<SdoStep>& steps);

}  // namespace cdpr::drivers::can
