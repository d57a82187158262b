#pragma once
// file access for the edge of the program: whole-file reads and atomic writes.
#include <cstdint>
#include <stdexcept>
#include <string>

namespace paddock::runner {

// a user-facing input or output problem; the message is what the user sees
class UserError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// inputs (scenarios, tracks, the sensors' files) are small: 64 MiB is far more
// than any of them needs
inline constexpr std::uint64_t kMaxInputBytes = 64ULL << 20;

// the whole file; throws UserError("path: cannot open ...", or "path: N
// bytes, more than ... for this kind of file" when it is larger than
// max_bytes: an input is read whole, so its size is bounded)
std::string read_file(const std::string& path, std::uint64_t max_bytes = kMaxInputBytes);

// writes to path.tmp.<pid>, flushes it to the disk (fsync), renames it over
// path and flushes the folder, so a reader (or the machine after a crash)
// never sees a half-written file: the old one or the new one. Creates missing
// parent folders. Throws UserError "path: cannot write: <the system's reason>"
// (a full disk: "No space left on device"), leaving no temporary file and the
// old file untouched
void write_file_atomic(const std::string& path, const std::string& content);

// this program's GNU build ID (the linker's hash of the executable, `readelf
// -n`) as hex; "" when it has none. Two programs with the same ID are the
// same code, so a result the code alone determines may be kept under it
std::string program_build_id();

// the folder for results kept between runs (the car's measured envelope):
// $PADDOCK_CACHE_DIR, else $XDG_CACHE_HOME/paddock, else ~/.cache/paddock;
// "" (keep nothing) when PADDOCK_CACHE_DIR is set empty or none is known.
// Anything in it may be deleted at any time
std::string cache_dir();

// a run's output folder while the run is not done: DIR/INCOMPLETE says so
// from the start (which checks the folder can be written, before the work)
// until done() has removed it, after every result is in place. A run that is
// interrupted (Ctrl-C, a kill, a crash) or fails leaves it behind, so an
// earlier run's files in DIR are never taken for this one's
class IncompleteMarker {
 public:
  // creates DIR (and its parents); throws UserError when it cannot be written
  IncompleteMarker(const std::string& dir, const std::string& what);
  void done();
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace paddock::runner
