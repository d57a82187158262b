#include "sim/runner/files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace paddock::runner {

namespace {

std::string reason() { return std::strerror(errno); }

// write all of it, through short writes and signals
bool write_all(int fd, const char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

}  // namespace

std::string read_file(const std::string& path, std::uint64_t max_bytes) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw UserError(path + ": cannot open: it is a folder, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UserError(path + ": cannot open: " + reason());
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > max_bytes) {
    throw UserError(path + ": " + std::to_string(size) + " bytes, more than the " + std::to_string(max_bytes) +
                    " this kind of file may have: refused");
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw UserError(path + ": read error");
  return ss.str();
}

void write_file_atomic(const std::string& path, const std::string& content) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path()) {
    fs::create_directories(target.parent_path(), ec);
    if (ec) throw UserError(path + ": cannot create folder " + target.parent_path().string() + ": " + ec.message());
  }
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw UserError(path + ": cannot write: " + reason());
  if (!write_all(fd, content.data(), content.size()) || ::fsync(fd) != 0) {
    const std::string why = reason();
    ::close(fd);
    fs::remove(tmp, ec);
    throw UserError(path + ": cannot write: " + why);
  }
  if (::close(fd) != 0) {
    const std::string why = reason();
    fs::remove(tmp, ec);
    throw UserError(path + ": cannot write: " + why);
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw UserError(path + ": cannot rename into place: " + ec.message());
  }
  // the rename itself on the disk
  const std::string dir = target.has_parent_path() ? target.parent_path().string() : std::string(".");
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

IncompleteMarker::IncompleteMarker(const std::string& dir, const std::string& what) : path_(dir + "/INCOMPLETE") {
  write_file_atomic(path_, what + "\nThis folder's results are not (all) this run's: it was interrupted or failed before it wrote them.\n");
}

void IncompleteMarker::done() {
  std::error_code ec;
  std::filesystem::remove(path_, ec);
  if (ec) throw UserError(path_ + ": cannot remove: " + ec.message());
}

}  // namespace paddock::runner
