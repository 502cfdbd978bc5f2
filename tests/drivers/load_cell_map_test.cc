// The load-cell register map: value types, the four byte orders, decimals,
// scale, units, status flags with either polarity and a sign bit, checked
// against register values written out by hand.

#include "drivers/modbus/load_cell_map.h"

#include <cmath>
#include <cstdint>

#include <gtest/gtest.h>

namespace cdpr::drivers::modbus {
namespace {

LoadCellMap map_of(ValueType type, ByteOrder order) {
  LoadCellMap map;
  map.value_type = type;
  map.byte_order = order;
  map.stable = {};
  map.error = {};
  map.status_address = -1;
  return map;
}

TEST(LoadCellMap, AssemblesInt32InAllFourByteOrders) {
  // GIVEN 0x12345678 = 305419896 laid out as each order says (bytes A=12 B=34 C=56 D=78)
  struct Case {
    ByteOrder order;
    std::uint16_t registers[2];
  };
  const Case cases[] = {{ByteOrder::kABCD, {0x1234, 0x5678}},
                        {ByteOrder::kCDAB, {0x5678, 0x1234}},
                        {ByteOrder::kBADC, {0x3412, 0x7856}},
                        {ByteOrder::kDCBA, {0x7856, 0x3412}}};
  for (const Case& c : cases) {
    // WHEN decoded THEN the same number comes out, and encoding gives the same registers
    const LoadCellMap map = map_of(ValueType::kInt32, c.order);
    const auto reading = decode_load_cell(map, c.registers);
    ASSERT_TRUE(reading.ok()) << reading.status().to_string();
    EXPECT_EQ(reading.value().tension_n, 305419896.0) << static_cast<int>(c.order);
    std::uint16_t again[2] = {};
    encode_load_cell(map, 305419896.0, true, false, again);
    EXPECT_EQ(again[0], c.registers[0]);
    EXPECT_EQ(again[1], c.registers[1]);
  }
}

TEST(LoadCellMap, Float32ByteSwappedAndInt16WithDecimalPoint) {
  // GIVEN 1.5f = 0x3FC00000 in DCBA (little-endian): registers 0x0000, 0xC03F
  const std::uint16_t float_registers[2] = {0x0000, 0xC03F};
  const auto f = decode_load_cell(map_of(ValueType::kFloat32, ByteOrder::kDCBA), float_registers);
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(f.value().tension_n, 1.5);
  // GIVEN int16 -1234 = 0xFB2E with two decimals, bytes swapped (BADC: 0x2EFB)
  LoadCellMap map = map_of(ValueType::kInt16, ByteOrder::kBADC);
  map.decimals = 2;
  const std::uint16_t int16_register[1] = {0x2EFB};
  const auto i = decode_load_cell(map, int16_register);
  ASSERT_TRUE(i.ok());
  EXPECT_NEAR(i.value().tension_n, -12.34, 1e-12);
  // AND uint16 reads 0xFB2E as 64302
  const std::uint16_t uint16_register[1] = {0xFB2E};
  EXPECT_EQ(decode_load_cell(map_of(ValueType::kUint16, ByteOrder::kABCD), uint16_register).value().tension_n, 64302.0);
}

TEST(LoadCellMap, UnitsAndScaleGiveNewtons) {
  const std::uint16_t registers[2] = {0x0000, 1000};
  LoadCellMap map = map_of(ValueType::kInt32, ByteOrder::kABCD);
  map.unit = ForceUnit::kKilogram;
  EXPECT_NEAR(decode_load_cell(map, registers).value().tension_n, 9806.65, 1e-9);
  map.unit = ForceUnit::kPoundForce;
  EXPECT_NEAR(decode_load_cell(map, registers).value().tension_n, 4448.2216152605, 1e-9);
  map.unit = ForceUnit::kNewton;
  map.scale = -0.5;
  EXPECT_NEAR(decode_load_cell(map, registers).value().tension_n, -500.0, 1e-12);
}

TEST(LoadCellMap, StatusFlagsHonourTheirPolarity) {
  // GIVEN "data ok" (bit 1, error when clear) and "motion" (bit 2, stable when clear) after the value
  LoadCellMap map = map_of(ValueType::kInt32, ByteOrder::kABCD);
  map.status_address = 2;
  map.error = {0x0002, false};
  map.stable = {0x0004, false};
  std::uint16_t registers[3] = {0, 5, 0x0002};
  // WHEN data ok, no motion THEN stable and accepted
  auto reading = decode_load_cell(map, registers);
  ASSERT_TRUE(reading.ok());
  EXPECT_TRUE(reading.value().stable);
  // WHEN in motion THEN not stable
  registers[2] = 0x0006;
  EXPECT_FALSE(decode_load_cell(map, registers).value().stable);
  // WHEN data ok is clear THEN a device fault naming the status word
  registers[2] = 0x0004;
  reading = decode_load_cell(map, registers);
  EXPECT_EQ(reading.status().code(), hal::ErrorCode::kDeviceFault);
  EXPECT_NE(reading.status().message().find("status register 4"), std::string::npos);
}

TEST(LoadCellMap, StatusBeforeTheValueAndASignBit) {
  // GIVEN the status register before the value, the value a magnitude with a sign bit
  LoadCellMap map = map_of(ValueType::kUint32, ByteOrder::kABCD);
  map.value_address = 7;
  map.status_address = 6;
  map.sign_mask = 0x0080;
  const RegisterSpan span = register_span(map);
  EXPECT_EQ(span.first, 6);
  EXPECT_EQ(span.count, 3);
  const std::uint16_t registers[3] = {0x0080, 0, 250};
  EXPECT_EQ(decode_load_cell(map, registers).value().tension_n, -250.0);
  // AND encoding a negative value sets the bit and writes the magnitude
  std::uint16_t again[3] = {};
  encode_load_cell(map, -250.0, false, false, again);
  EXPECT_EQ(again[0], 0x0080);
  EXPECT_EQ(again[2], 250);
}

TEST(LoadCellMap, ValidationNamesTheProblem) {
  LoadCellMap map;
  EXPECT_EQ(validate(map), "");
  map.status_address = 1;
  EXPECT_NE(validate(map).find("overlaps"), std::string::npos);
  map.status_address = 40;
  EXPECT_NE(validate(map).find("apart"), std::string::npos);
  map.status_address = 2;
  map.decimals = 2;
  EXPECT_NE(validate(map).find("integer"), std::string::npos);
  map.value_type = ValueType::kInt32;
  map.scale = 0.0;
  EXPECT_NE(validate(map).find("scale"), std::string::npos);
  map.scale = 1.0;
  map.status_address = -1;
  EXPECT_NE(validate(map).find("status_address"), std::string::npos);
}

TEST(LoadCellMap, NonFiniteFloatIsADeviceFault) {
  const std::uint16_t registers[2] = {0x7FC0, 0x0000};  // quiet NaN
  EXPECT_EQ(decode_load_cell(map_of(ValueType::kFloat32, ByteOrder::kABCD), registers).status().code(),
            hal::ErrorCode::kDeviceFault);
}

}  // namespace
}  // namespace cdpr::drivers::modbus
