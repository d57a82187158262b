#pragma once
// file access for the edge of the program: whole-file reads and atomic writes.
#include <stdexcept>
#include <string>

namespace paddock::runner {

// a user-facing input or output problem; the message is what the user sees
class UserError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// the whole file; throws UserError("path: cannot open ...")
std::string read_file(const std::string& path);

// writes to path.tmp.<pid> and renames over path, so a reader never sees a
// half-written file; creates missing parent folders; throws UserError
void write_file_atomic(const std::string& path, const std::string& content);

}  // namespace paddock::runner
