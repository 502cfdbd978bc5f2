// The SDO client against hand-written server frames of CiA 301's SDO
// protocols (byte 0 command specifiers spelled out in each test).

#include "drivers/can/sdo_client.h"

#include <string>

#include <gtest/gtest.h>

namespace cdpr::drivers::can {
namespace {

constexpr int kNode = 5;

CanFrame response(std::initializer_list<std::uint8_t> bytes) {
  CanFrame frame;
  frame.id = 0x580 + kNode;
  frame.len = 8;
  int i = 0;
  for (std::uint8_t b : bytes) frame.data[i++] = b;
  return frame;
}

TEST(SdoClient, ExpeditedDownload) {
  // GIVEN a client WHEN it writes 0x6060:00 = 1 (one byte)
  SdoClient sdo(kNode, 100'000);
  sdo.start_download_value(0x6060, 0, 1, 1, 0);
  const auto sent = sdo.poll(0);
  // THEN the request is 0x2F (expedited, size, n = 3) on 0x605 with index and data
  ASSERT_TRUE(sent);
  EXPECT_EQ(sent->id, 0x605u);
  EXPECT_EQ(sent->data[0], 0x2F);
  EXPECT_EQ(sent->data[1], 0x60);
  EXPECT_EQ(sent->data[2], 0x60);
  EXPECT_EQ(sent->data[4], 1);
  EXPECT_TRUE(sdo.busy());
  // WHEN the server confirms THEN done
  EXPECT_TRUE(sdo.on_frame(response({0x60, 0x60, 0x60, 0x00}), 1'000));
  EXPECT_EQ(sdo.state(), SdoClient::State::kDone);
  EXPECT_FALSE(sdo.poll(2'000));
}

TEST(SdoClient, ExpeditedUpload) {
  SdoClient sdo(kNode, 100'000);
  sdo.start_upload(0x1018, 1, 0);
  const auto sent = sdo.poll(0);
  ASSERT_TRUE(sent);
  EXPECT_EQ(sent->data[0], 0x40);
  // 0x43: expedited, size indicated, 4 bytes
  sdo.on_frame(response({0x43, 0x18, 0x10, 0x01, 0x78, 0x56, 0x34, 0x12}), 1'000);
  ASSERT_EQ(sdo.state(), SdoClient::State::kDone);
  EXPECT_EQ(sdo.size(), 4u);
  EXPECT_EQ(sdo.value(), 0x12345678u);
}

TEST(SdoClient, SegmentedUploadChecksTheToggleBit) {
  // GIVEN an upload of 0x1008 (device name, 10 bytes) announced segmented
  SdoClient sdo(kNode, 100'000);
  sdo.start_upload(0x1008, 0, 0);
  (void)sdo.poll(0);
  sdo.on_frame(response({0x41, 0x08, 0x10, 0x00, 10, 0, 0, 0}), 1'000);
  // THEN the first segment request has toggle 0
  auto sent = sdo.poll(1'000);
  ASSERT_TRUE(sent);
  EXPECT_EQ(sent->data[0], 0x60);
  // WHEN 7 bytes come with toggle 0 THEN the next request has toggle 1
  sdo.on_frame(response({0x00, 'w', 'i', 'n', 'c', 'h', '-', 'd'}), 2'000);
  sent = sdo.poll(2'000);
  ASSERT_TRUE(sent);
  EXPECT_EQ(sent->data[0], 0x70);
  // WHEN the last 3 bytes come with toggle 1 (n = 4 unused, c = 1) THEN done
  sdo.on_frame(response({0x19, 'r', 'v', '1', 0, 0, 0, 0}), 3'000);
  ASSERT_EQ(sdo.state(), SdoClient::State::kDone);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(sdo.bytes()), sdo.size()), "winch-drv1");

  // GIVEN another segmented upload WHEN the server repeats toggle 0
  sdo.clear();
  sdo.start_upload(0x1008, 0, 10'000);
  (void)sdo.poll(10'000);
  sdo.on_frame(response({0x41, 0x08, 0x10, 0x00, 20, 0, 0, 0}), 11'000);
  (void)sdo.poll(11'000);
  sdo.on_frame(response({0x00, 1, 2, 3, 4, 5, 6, 7}), 12'000);
  (void)sdo.poll(12'000);
  sdo.on_frame(response({0x00, 1, 2, 3, 4, 5, 6, 7}), 13'000);
  // THEN the transfer fails and the client aborts with 0x05030000
  ASSERT_EQ(sdo.state(), SdoClient::State::kFailed);
  EXPECT_NE(sdo.error().find("toggle"), std::string::npos) << sdo.error();
  sent = sdo.poll(13'000);
  ASSERT_TRUE(sent);
  EXPECT_EQ(sent->data[0], 0x80);
  EXPECT_EQ(sent->data[7], 0x05);
  EXPECT_EQ(sent->data[6], 0x03);
}

TEST(SdoClient, SegmentedDownload) {
  // GIVEN a write of 9 bytes
  SdoClient sdo(kNode, 100'000);
  const std::uint8_t data[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  sdo.start_download(0x2000, 0, data, sizeof(data), 0);
  auto sent = sdo.poll(0);
  ASSERT_TRUE(sent);
  EXPECT_EQ(sent->data[0], 0x21);  // segmented, size indicated
  EXPECT_EQ(sent->data[4], 9);
  sdo.on_frame(response({0x60, 0x00, 0x20, 0x00}), 1'000);
  // THEN 7 bytes with toggle 0, not last
  sent = sdo.poll(1'000);
  ASSERT_TRUE(sent);
  EXPECT_EQ(sent->data[0], 0x00);
  EXPECT_EQ(sent->data[7], 7);
  sdo.on_frame(response({0x20}), 2'000);
  // THEN 2 bytes with toggle 1, n = 5, last
  sent = sdo.poll(2'000);
  ASSERT_TRUE(sent);
  EXPECT_EQ(sent->data[0], 0x10 | 5 << 1 | 1);
  EXPECT_EQ(sent->data[1], 8);
  sdo.on_frame(response({0x30}), 3'000);
  EXPECT_EQ(sdo.state(), SdoClient::State::kDone);
}

TEST(SdoClient, AbortCodeIsDecodedIntoTheError) {
  SdoClient sdo(kNode, 100'000);
  sdo.start_upload(0x6002, 0, 0);
  (void)sdo.poll(0);
  sdo.on_frame(response({0x80, 0x02, 0x60, 0x00, 0x00, 0x00, 0x02, 0x06}), 1'000);
  ASSERT_EQ(sdo.state(), SdoClient::State::kFailed);
  EXPECT_EQ(sdo.abort_code(), 0x06020000u);
  EXPECT_EQ(sdo.error(), "node 5 SDO read 0x6002:0x00: abort 0x06020000 (object does not exist in the object dictionary)");
  EXPECT_FALSE(sdo.poll(2'000));  // the server aborted: nothing to send back
}

TEST(SdoClient, TimeoutAbortsTheTransfer) {
  // GIVEN a request sent at t = 0 WHEN nothing answers for longer than 100 ms
  SdoClient sdo(kNode, 100'000);
  sdo.start_upload(0x1000, 0, 0);
  (void)sdo.poll(0);
  EXPECT_FALSE(sdo.poll(100'000));
  EXPECT_TRUE(sdo.busy());
  const auto sent = sdo.poll(100'001);
  // THEN it failed and sends abort 0x05040000
  EXPECT_EQ(sdo.state(), SdoClient::State::kFailed);
  EXPECT_NE(sdo.error().find("no answer within 100 ms"), std::string::npos) << sdo.error();
  ASSERT_TRUE(sent);
  EXPECT_EQ(sent->data[0], 0x80);
  EXPECT_EQ(sent->data[6], 0x04);
  // AND a late answer is swallowed without effect
  EXPECT_TRUE(sdo.on_frame(response({0x43, 0x00, 0x10, 0x00, 1, 2, 3, 4}), 200'000));
  EXPECT_EQ(sdo.state(), SdoClient::State::kFailed);
}

TEST(SdoClient, OtherNodesFramesAreNotConsumed) {
  SdoClient sdo(kNode, 100'000);
  CanFrame frame = response({0x60});
  frame.id = 0x586;
  EXPECT_FALSE(sdo.on_frame(frame, 0));
}

}  // namespace
}  // namespace cdpr::drivers::can
