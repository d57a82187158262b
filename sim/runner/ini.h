#pragma once
// our INI dialect: [section], key = value, ; and # comments, include = path.
//
//   ; a comment            # also a comment
//   include = vehicles/default.ini   ; relative to this file; may appear anywhere
//   [control]
//   lateral = combined     ; a trailing comment after whitespace
//
// An include splices the other file's entries in at that point; after it the
// including file continues in the section it was in. Later entries override
// earlier ones (a scenario includes a vehicle, then changes a key of it); the
// same key twice in one file is an error. Include cycles are errors.
#include <string>
#include <vector>

namespace paddock::runner {

struct IniEntry {
  std::string section;
  std::string key;
  std::string value;
  std::string file;  // where it was written, for messages
  int line = 0;

  std::string where() const { return file + ":" + std::to_string(line); }
};

// every entry of a file and its includes, in reading order; throws UserError
// with "file:line: what is wrong" for syntax errors, missing files and cycles
std::vector<IniEntry> read_ini_file(const std::string& path);

// `s` without its leading and trailing blanks (spaces, tabs, carriage returns)
std::string trim(const std::string& s);

// the same for text already in memory; includes are read relative to base_dir
// (an empty base_dir: the text may include nothing, e.g. a log's scenario)
std::vector<IniEntry> parse_ini_text(const std::string& text, const std::string& source,
                                     const std::string& base_dir);

}  // namespace paddock::runner
