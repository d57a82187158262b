#include "sim/runner/files.h"

#include <elf.h>
#include <fcntl.h>
#include <link.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
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

std::string program_build_id() {
  // the main program is the first object dl_iterate_phdr reports; its
  // PT_NOTE segments hold the note GNU / NT_GNU_BUILD_ID
  std::string id;
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void* out) -> int {
        for (int i = 0; i < info->dlpi_phnum; ++i) {
          const ElfW(Phdr)& ph = info->dlpi_phdr[i];
          if (ph.p_type != PT_NOTE) continue;
          const char* p = reinterpret_cast<const char*>(info->dlpi_addr + ph.p_vaddr);
          const char* const end = p + ph.p_memsz;
          const auto align4 = [](std::size_t n) { return (n + 3) & ~std::size_t{3}; };
          while (p + sizeof(ElfW(Nhdr)) <= end) {
            const auto* note = reinterpret_cast<const ElfW(Nhdr)*>(p);
            const char* name = p + sizeof(ElfW(Nhdr));
            const unsigned char* desc = reinterpret_cast<const unsigned char*>(name + align4(note->n_namesz));
            if (reinterpret_cast<const char*>(desc) + note->n_descsz > end) break;
            if (note->n_type == NT_GNU_BUILD_ID && note->n_namesz == 4 && std::memcmp(name, "GNU", 4) == 0) {
              static const char kHex[] = "0123456789abcdef";
              auto& text = *static_cast<std::string*>(out);
              for (unsigned k = 0; k < note->n_descsz; ++k) {
                text += kHex[desc[k] >> 4];
                text += kHex[desc[k] & 15];
              }
              return 1;
            }
            p = reinterpret_cast<const char*>(desc) + align4(note->n_descsz);
          }
        }
        return 1;  // the main program only
      },
      &id);
  return id;
}

std::string cache_dir() {
  if (const char* own = std::getenv("PADDOCK_CACHE_DIR")) return own;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/paddock";
  if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/paddock";
  return "";
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
