// The CAN transports: the wire record is struct can_frame byte for byte, over
// a socketpair and over a listening Unix socket; SocketCAN fails clearly
// where the kernel has no AF_CAN or no interface.

#include "drivers/can/fd_can_transport.h"

#include <linux/can.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

namespace cdpr::drivers::can {
namespace {

TEST(FdCanTransport, SendsStructCanFrameVerbatim) {
  // GIVEN a transport on one end of a socketpair
  int fds[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
  FdCanTransport transport(fds[0], "a");
  // WHEN it sends a 3-byte frame with id 0x181
  CanFrame frame;
  frame.id = 0x181;
  frame.len = 3;
  frame.data = {0xAA, 0xBB, 0xCC, 0, 0, 0, 0, 0};
  ASSERT_TRUE(transport.send(frame).ok());
  // THEN the other end reads exactly one struct can_frame with those fields
  struct can_frame raw;
  ASSERT_EQ(::read(fds[1], &raw, sizeof(raw)), static_cast<ssize_t>(sizeof(raw)));
  EXPECT_EQ(raw.can_id, 0x181u);
  EXPECT_EQ(raw.can_dlc, 3);
  EXPECT_EQ(raw.data[0], 0xAA);
  EXPECT_EQ(raw.data[2], 0xCC);
  EXPECT_EQ(raw.data[3], 0);
  ::close(fds[1]);
}

TEST(FdCanTransport, ReassemblesRecordsSplitAcrossReadsAndSkipsMalformedOnes) {
  // GIVEN a transport and a peer writing raw records
  int fds[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
  FdCanTransport transport(fds[0], "b");
  struct can_frame bad{};
  bad.can_id = 0x123 | CAN_EFF_FLAG;  // extended frames are not ours
  struct can_frame good{};
  good.can_id = 0x701;
  good.can_dlc = 1;
  good.data[0] = 0x05;
  // WHEN the bad record, then the good one in two pieces, arrive
  ASSERT_EQ(::write(fds[1], &bad, sizeof(bad)), 16);
  const auto* bytes = reinterpret_cast<const unsigned char*>(&good);
  ASSERT_EQ(::write(fds[1], bytes, 5), 5);
  CanFrame frame;
  // THEN the bad one is refused as corrupt, the partial one waits ...
  EXPECT_EQ(transport.receive(frame, 100'000).status().code(), hal::ErrorCode::kCorruptData);
  const hal::Result<bool> partial = transport.receive(frame, 0);
  ASSERT_TRUE(partial.ok());
  EXPECT_FALSE(partial.value());
  // ... and arrives whole when its rest does
  ASSERT_EQ(::write(fds[1], bytes + 5, 11), 11);
  const hal::Result<bool> whole = transport.receive(frame, 100'000);
  ASSERT_TRUE(whole.ok());
  ASSERT_TRUE(whole.value());
  EXPECT_EQ(frame.id, 0x701u);
  EXPECT_EQ(frame.len, 1);
  EXPECT_EQ(frame.data[0], 0x05);
  // WHEN the peer closes THEN not connected
  ::close(fds[1]);
  EXPECT_EQ(transport.receive(frame, 100'000).status().code(), hal::ErrorCode::kNotConnected);
}

TEST(FdCanTransport, ReceiveTimesOutWithinItsBound) {
  int fds[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
  FdCanTransport transport(fds[0], "c");
  CanFrame frame;
  const hal::Result<bool> got = transport.receive(frame, 20'000);
  ASSERT_TRUE(got.ok());
  EXPECT_FALSE(got.value());
  ::close(fds[1]);
}

TEST(FdCanTransport, ConnectsToAListeningUnixSocket) {
  // GIVEN a listening Unix socket in a fresh directory
  char dir[] = "/tmp/cdpr-can-XXXXXX";
  ASSERT_NE(::mkdtemp(dir), nullptr);
  const std::string path = std::string(dir) + "/can.sock";
  const int listener = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strcpy(address.sun_path, path.c_str());
  ASSERT_EQ(::bind(listener, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0);
  ASSERT_EQ(::listen(listener, 1), 0);
  // WHEN a transport connects and the server sends a frame through the accepted socket
  auto client = FdCanTransport::connect_unix(path);
  ASSERT_TRUE(client.ok()) << client.status().to_string();
  FdCanTransport server(::accept(listener, nullptr, nullptr), "server");
  CanFrame sent;
  sent.id = 0x7FF;
  sent.len = 8;
  sent.data = {1, 2, 3, 4, 5, 6, 7, 8};
  ASSERT_TRUE(server.send(sent).ok());
  // THEN the client receives it intact
  CanFrame received;
  const hal::Result<bool> got = client.value()->receive(received, 200'000);
  ASSERT_TRUE(got.ok() && got.value());
  EXPECT_EQ(received.id, sent.id);
  EXPECT_EQ(received.data, sent.data);
  ::close(listener);
  ::unlink(path.c_str());
  ::rmdir(dir);
}

TEST(FdCanTransport, MissingUnixSocketIsNotConnected) {
  auto client = FdCanTransport::connect_unix("/tmp/cdpr-no-such-dir/can.sock");
  ASSERT_FALSE(client.ok());
  EXPECT_EQ(client.status().code(), hal::ErrorCode::kNotConnected);
}

TEST(FdCanTransport, SocketCanFailsWithAClearReason) {
  // GIVEN this machine (no AF_CAN in the kernel, or no such interface)
  // WHEN opening a SocketCAN interface that does not exist
  auto transport = FdCanTransport::open_socketcan("cdprtest9");
  // THEN it fails as unsupported or not connected, naming the interface
  ASSERT_FALSE(transport.ok());
  const hal::ErrorCode code = transport.status().code();
  EXPECT_TRUE(code == hal::ErrorCode::kUnsupported || code == hal::ErrorCode::kNotConnected)
      << transport.status().to_string();
  EXPECT_NE(transport.status().message().find("cdprtest9"), std::string::npos);
}

TEST(FdCanTransport, RefusesOutOfRangeFrames) {
  int fds[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
  FdCanTransport transport(fds[0], "d");
  CanFrame frame;
  frame.id = 0x800;
  EXPECT_EQ(transport.send(frame).code(), hal::ErrorCode::kInvalidArgument);
  ::close(fds[1]);
}

}  // namespace
}  // namespace cdpr::drivers::can
