#pragma once
// Small blocking-with-timeout socket helpers shared by the CAN (Unix stream)
// and pose stream transports. All fds returned are non-blocking and
// close-on-exec; the caller owns them.

#include <string>
#include <string_view>

#include "hal/clock.h"
#include "hal/status.h"

namespace cdpr::drivers {

// Connects a Unix stream socket to `path`. Errors: kNotConnected (no
// listener), kInvalidArgument (path too long for sockaddr_un).
hal::Result<int> connect_unix_stream(const std::string& path);

// Connects TCP to host:port (numeric or name, IPv4/IPv6), waiting at most
// timeout_us. Errors: kNotConnected, kTimeout, kInvalidArgument.
hal::Result<int> connect_tcp(const std::string& host, int port, hal::TimeUs timeout_us);

// "unix:/run/x.sock" or "tcp:host:port" -> a connected fd (see above).
hal::Result<int> connect_endpoint(std::string_view endpoint, hal::TimeUs timeout_us);

// Starts connecting to "unix:<path>" or "tcp:<host>:<port>" without waiting:
// the fd returned may still be connecting (see connect_progress). A TCP host
// name is resolved first (getaddrinfo blocks for DNS: give a numeric address
// where that matters); the first address is tried. Errors: kNotConnected
// (refused, unreachable, no listener), kInvalidArgument (bad endpoint).
hal::Result<int> start_connect_endpoint(std::string_view endpoint);
// Whether a connect started by start_connect_endpoint has finished, without
// waiting: true connected, false still in progress; an error when it failed.
hal::Result<bool> connect_progress(int fd, const std::string& device);

// Waits at most timeout_us until `fd` is readable (or writable). true: ready;
// false: timed out. Errors: kIoError from poll(). EINTR restarts the wait.
hal::Result<bool> wait_readable(int fd, hal::TimeUs timeout_us);
hal::Result<bool> wait_writable(int fd, hal::TimeUs timeout_us);

// Sets O_NONBLOCK; false on failure (errno set).
bool set_nonblocking(int fd);

}  // namespace cdpr::drivers
