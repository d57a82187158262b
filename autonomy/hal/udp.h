#pragma once
// a UDP socket (IPv4): the car binary's ports and the simulator's side of
// transport = udp. Errors throw std::runtime_error naming the address and
// the system's reason.
#include <netinet/in.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/time.h"

namespace paddock::hal {

class UdpSocket {
 public:
  // bound to host:port; port 0 takes any free port (port() says which)
  UdpSocket(const std::string& host, int port);
  ~UdpSocket();
  UdpSocket(UdpSocket&& o) noexcept;
  UdpSocket& operator=(UdpSocket&&) = delete;
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;

  int fd() const { return fd_; }
  int port() const { return port_; }
  // the address of host:port; throws for a host that is no IPv4 address
  static sockaddr_in address(const std::string& host, int port);

  // the next datagram into `buf` (resized to it), waiting up to `timeout`
  // (ns; 0: not at all, < 0: for ever); nothing at the timeout. from: the
  // sender's address
  bool receive(std::vector<std::uint8_t>& buf, TimeNs timeout, sockaddr_in* from = nullptr);
  void send_to(const sockaddr_in& to, const std::uint8_t* data, std::size_t size);

 private:
  int fd_ = -1;
  int port_ = 0;
  std::string name_;  // host:port, for errors
};

}  // namespace paddock::hal
