#pragma once
// The object dictionary of one simulated CANopen device (CiA 301): entries
// of 1, 2 or 4 bytes by index and sub-index with their access rights and
// whether a PDO may map them, plus their power-on defaults so an NMT reset
// brings them back. Written from the standard's tables, independently of
// the master's code in drivers/can, so a misreading on one side shows as a
// failure on the other.
//
// Abort codes returned are CiA 301's (0 = success). Not thread-safe.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace cdpr::virtual_robot {

// CiA 301 SDO abort codes the devices use.
namespace abort_code {
constexpr std::uint32_t kToggle = 0x05030000;
constexpr std::uint32_t kCommand = 0x05040001;
constexpr std::uint32_t kUnsupportedAccess = 0x06010000;
constexpr std::uint32_t kReadOnly = 0x06010002;
constexpr std::uint32_t kNoObject = 0x06020000;
constexpr std::uint32_t kNotMappable = 0x06040041;
constexpr std::uint32_t kPdoTooLong = 0x06040042;
constexpr std::uint32_t kLength = 0x06070010;
constexpr std::uint32_t kNoSubindex = 0x06090011;
constexpr std::uint32_t kInvalidValue = 0x06090030;
constexpr std::uint32_t kValueTooHigh = 0x06090031;
constexpr std::uint32_t kValueTooLow = 0x06090032;
constexpr std::uint32_t kDeviceState = 0x08000022;
}  // namespace abort_code

enum class Access { kReadOnly, kReadWrite };

struct OdEntry {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::uint8_t size = 4;  // bytes: 1, 2 or 4
  Access access = Access::kReadWrite;
  bool mappable = false;
  std::uint32_t value = 0;
  std::uint32_t default_value = 0;
  bool is_signed = false;                 // INTEGER8/16/32: limits compare signed
  std::optional<std::int64_t> low, high;  // an SDO write outside them is refused
};

class ObjectDictionary {
 public:
  // Adds an entry whose value starts at (and resets to) `value`.
  void add(std::uint16_t index, std::uint8_t subindex, std::uint8_t size, Access access, bool mappable,
           std::uint32_t value);
  // Every entry back to its default (NMT reset node); with
  // `communication_only`, only 0x1000-0x1FFF (NMT reset communication).
  void reset(bool communication_only);
  // The range an SDO write must keep to (the EDS's LowLimit/HighLimit).
  void set_limits(std::uint16_t index, std::uint8_t subindex, bool is_signed, std::optional<std::int64_t> low,
                  std::optional<std::int64_t> high);
  // 0 when `value` is within the entry's range, else abort 0x06090031 / 0x06090032.
  static std::uint32_t check_range(const OdEntry& entry, std::uint32_t value);

  OdEntry* find(std::uint16_t index, std::uint8_t subindex);
  const OdEntry* find(std::uint16_t index, std::uint8_t subindex) const;
  bool has_index(std::uint16_t index) const;
  // 0 on success, else the abort code (no such object or sub-index).
  std::uint32_t check_exists(std::uint16_t index, std::uint8_t subindex) const;

  // The device's own reads and writes (no access check).
  std::uint32_t get(std::uint16_t index, std::uint8_t subindex) const;
  void set(std::uint16_t index, std::uint8_t subindex, std::uint32_t value);
  std::int32_t get_signed(std::uint16_t index, std::uint8_t subindex) const;

 private:
  std::vector<OdEntry> entries_;
};

}  // namespace cdpr::virtual_robot
