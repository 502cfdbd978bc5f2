#include "virtual-robot/object_dictionary.h"

#include <cstdlib>

namespace cdpr::virtual_robot {

void ObjectDictionary::add(std::uint16_t index, std::uint8_t subindex, std::uint8_t size, Access access, bool mappable,
                           std::uint32_t value) {
  entries_.push_back(OdEntry{index, subindex, size, access, mappable, value, value, false, std::nullopt, std::nullopt});
}

void ObjectDictionary::reset(bool communication_only) {
  for (OdEntry& e : entries_) {
    if (!communication_only || (e.index >= 0x1000 && e.index <= 0x1FFF)) e.value = e.default_value;
  }
}

void ObjectDictionary::set_limits(std::uint16_t index, std::uint8_t subindex, bool is_signed,
                                  std::optional<std::int64_t> low, std::optional<std::int64_t> high) {
  OdEntry* e = find(index, subindex);
  if (e == nullptr) std::abort();
  e->is_signed = is_signed;
  e->low = low;
  e->high = high;
}

std::uint32_t ObjectDictionary::check_range(const OdEntry& entry, std::uint32_t value) {
  std::int64_t v = value;
  if (entry.is_signed && entry.size == 1) v = static_cast<std::int8_t>(value & 0xFF);
  if (entry.is_signed && entry.size == 2) v = static_cast<std::int16_t>(value & 0xFFFF);
  if (entry.is_signed && entry.size == 4) v = static_cast<std::int32_t>(value);
  if (entry.low && v < *entry.low) return abort_code::kValueTooLow;
  if (entry.high && v > *entry.high) return abort_code::kValueTooHigh;
  return 0;
}

OdEntry* ObjectDictionary::find(std::uint16_t index, std::uint8_t subindex) {
  for (OdEntry& e : entries_) {
    if (e.index == index && e.subindex == subindex) return &e;
  }
  return nullptr;
}

const OdEntry* ObjectDictionary::find(std::uint16_t index, std::uint8_t subindex) const {
  return const_cast<ObjectDictionary*>(this)->find(index, subindex);
}

bool ObjectDictionary::has_index(std::uint16_t index) const {
  for (const OdEntry& e : entries_) {
    if (e.index == index) return true;
  }
  return false;
}

std::uint32_t ObjectDictionary::check_exists(std::uint16_t index, std::uint8_t subindex) const {
  if (find(index, subindex) != nullptr) return 0;
  return has_index(index) ? abort_code::kNoSubindex : abort_code::kNoObject;
}

std::uint32_t ObjectDictionary::get(std::uint16_t index, std::uint8_t subindex) const {
  const OdEntry* e = find(index, subindex);
  if (e == nullptr) std::abort();  // the device's own object: a broken invariant
  return e->value;
}

void ObjectDictionary::set(std::uint16_t index, std::uint8_t subindex, std::uint32_t value) {
  OdEntry* e = find(index, subindex);
  if (e == nullptr) std::abort();
  e->value = value;
}

std::int32_t ObjectDictionary::get_signed(std::uint16_t index, std::uint8_t subindex) const {
  const OdEntry* e = find(index, subindex);
  if (e == nullptr) std::abort();
  // Sign-extend 8- and 16-bit INTEGER objects.
  if (e->size == 1) return static_cast<std::int8_t>(e->value & 0xFF);
  if (e->size == 2) return static_cast<std::int16_t>(e->value & 0xFFFF);
  return static_cast<std::int32_t>(e->value);
}

}  // namespace cdpr::virtual_robot
