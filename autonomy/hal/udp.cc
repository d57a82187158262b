#include "autonomy/hal/udp.h"

#include <arpa/inet.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

namespace paddock::hal {
namespace {

std::string reason() { return std::strerror(errno); }

}  // namespace

sockaddr_in UdpSocket::address(const std::string& host, int port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  if (port < 0 || port > 65535 || inet_pton(AF_INET, host.c_str(), &a.sin_addr) != 1)
    throw std::runtime_error(host + ":" + std::to_string(port) + ": expected an IPv4 address and a port 0..65535");
  return a;
}

UdpSocket::UdpSocket(const std::string& host, int port) : name_(host + ":" + std::to_string(port)) {
  const sockaddr_in a = address(host, port);
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error("UDP socket: " + reason());
  // room for a LiDAR rotation's burst (the kernel caps it at net.core.rmem_max)
  const int buffer = 8 << 20;
  ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &buffer, sizeof buffer);
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
    const std::string why = reason();
    ::close(fd_);
    throw std::runtime_error("cannot listen on UDP " + name_ + ": " + why);
  }
  sockaddr_in bound{};
  socklen_t len = sizeof bound;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &len);
  port_ = ntohs(bound.sin_port);
  name_ = host + ":" + std::to_string(port_);
}

UdpSocket::UdpSocket(UdpSocket&& o) noexcept : fd_(o.fd_), port_(o.port_), name_(std::move(o.name_)) { o.fd_ = -1; }

UdpSocket::~UdpSocket() {
  if (fd_ >= 0) ::close(fd_);
}

bool UdpSocket::receive(std::vector<std::uint8_t>& buf, TimeNs timeout, sockaddr_in* from) {
  buf.resize(65536);
  for (;;) {
    sockaddr_in src{};
    socklen_t len = sizeof src;
    const ssize_t n = ::recvfrom(fd_, buf.data(), buf.size(), MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&src), &len);
    if (n >= 0) {
      buf.resize(static_cast<std::size_t>(n));
      if (from) *from = src;
      return true;
    }
    if (errno == EINTR) continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK) throw std::runtime_error("UDP " + name_ + ": " + reason());
    if (timeout == 0) {
      buf.clear();
      return false;
    }
    pollfd p{fd_, POLLIN, 0};
    timespec ts{static_cast<time_t>(timeout / kNsPerSecond), static_cast<long>(timeout % kNsPerSecond)};
    const int r = ::ppoll(&p, 1, timeout < 0 ? nullptr : &ts, nullptr);
    if (r < 0 && errno == EINTR) {
      // a signal: the caller decides (its stop flag); no datagram this time
      buf.clear();
      return false;
    }
    if (r < 0) throw std::runtime_error("UDP " + name_ + ": " + reason());
    if (r == 0) {
      buf.clear();
      return false;
    }
    timeout = 0;  // readable: the next recvfrom has it
  }
}

void UdpSocket::send_to(const sockaddr_in& to, const std::uint8_t* data, std::size_t size) {
  for (;;) {
    const ssize_t n = ::sendto(fd_, data, size, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
    if (n == static_cast<ssize_t>(size)) return;
    if (n < 0 && errno == EINTR) continue;
    char addr[INET_ADDRSTRLEN] = "?";
    ::inet_ntop(AF_INET, &to.sin_addr, addr, sizeof addr);
    throw std::runtime_error("UDP send to " + std::string(addr) + ":" + std::to_string(ntohs(to.sin_port)) + ": " +
                             (n < 0 ? reason() : "sent in part"));
  }
}

}  // namespace paddock::hal
