#pragma once
// the paddock program run in the background, as a second process beside the
// test (the car binary): its output read line by line while it runs
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <optional>
#include <string>

namespace paddock::testing {

class Background {
 public:
  // `PADDOCK_BINARY args`, its stdout and stderr into a pipe
  explicit Background(const std::string& args) {
    int fds[2];
    if (::pipe(fds) != 0) std::abort();
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(fds[1], 1);
      ::dup2(fds[1], 2);
      ::close(fds[0]);
      ::close(fds[1]);
      const std::string command = "exec " + std::string(PADDOCK_BINARY) + " " + args;
      ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(fds[1]);
    fd_ = fds[0];
  }
  ~Background() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    if (fd_ >= 0) ::close(fd_);
  }
  Background(const Background&) = delete;
  Background& operator=(const Background&) = delete;

  // the next line of its output, waiting up to `seconds`; nothing at the
  // timeout or the end of its output
  std::optional<std::string> line(double seconds) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    for (;;) {
      const std::size_t nl = buffer_.find('\n');
      if (nl != std::string::npos) {
        std::string l = buffer_.substr(0, nl);
        output_ += buffer_.substr(0, nl + 1);
        buffer_.erase(0, nl + 1);
        return l;
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now());
      if (left.count() <= 0 || !read_some(static_cast<int>(left.count()))) return std::nullopt;
    }
  }
  void signal(int sig) { ::kill(pid_, sig); }
  // waits for it to exit (up to `seconds`, then kills it): its exit code,
  // -1 when it did not exit by itself; the rest of its output joins output()
  int wait(double seconds) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now());
      if (left.count() <= 0) {
        ::kill(pid_, SIGKILL);
        break;
      }
      if (!read_some(static_cast<int>(left.count()))) break;
    }
    int status = 0;
    ::waitpid(pid_, &status, 0);
    exited_ = true;
    output_ += buffer_;
    buffer_.clear();
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  // everything it printed so far (read by line() or wait())
  const std::string& output() const { return output_; }

 private:
  // false at the end of its output or the timeout
  bool read_some(int timeout_ms) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) <= 0) return false;
    char buf[4096];
    const ssize_t n = ::read(fd_, buf, sizeof buf);
    if (n <= 0) return false;
    buffer_.append(buf, static_cast<std::size_t>(n));
    return true;
  }

  pid_t pid_ = -1;
  int fd_ = -1;
  bool exited_ = false;
  std::string buffer_, output_;
};

}  // namespace paddock::testing
