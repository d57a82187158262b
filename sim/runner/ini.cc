#include "sim/runner/ini.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <utility>

#include "sim/runner/files.h"

namespace paddock::runner {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

namespace {

namespace fs = std::filesystem;

// a ';' or '#' that starts the line or follows whitespace begins a comment
std::string strip_comment(const std::string& s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    if ((s[i] == ';' || s[i] == '#') && (i == 0 || s[i - 1] == ' ' || s[i - 1] == '\t')) return s.substr(0, i);
  }
  return s;
}

bool valid_name(const std::string& s) {
  if (s.empty()) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.';
  });
}

class Reader {
 public:
  std::vector<IniEntry> entries;

  void parse(const std::string& text, const std::string& source, const fs::path& base_dir) {
    std::string section;
    std::map<std::pair<std::string, std::string>, int> seen;  // (section, key) -> line, this file only
    int line_no = 0;
    std::size_t pos = 0;
    while (pos <= text.size()) {
      const auto nl = text.find('\n', pos);
      const std::string raw = text.substr(pos, nl == std::string::npos ? std::string::npos : nl - pos);
      pos = nl == std::string::npos ? text.size() + 1 : nl + 1;
      ++line_no;
      const std::string where = source + ":" + std::to_string(line_no);
      const std::string line = trim(strip_comment(raw));
      if (line.empty()) continue;
      // a section header
      if (line.front() == '[') {
        if (line.back() != ']') throw UserError(where + ": malformed section header '" + line + "', expected [name]");
        section = trim(line.substr(1, line.size() - 2));
        if (!valid_name(section)) throw UserError(where + ": bad section name '" + section + "', expected letters, digits and _");
        continue;
      }
      // key = value
      const auto eq = line.find('=');
      if (eq == std::string::npos) throw UserError(where + ": expected 'key = value', '[section]' or a comment, got '" + line + "'");
      const std::string key = trim(line.substr(0, eq));
      const std::string value = trim(line.substr(eq + 1));
      if (!valid_name(key)) throw UserError(where + ": bad key '" + key + "', expected letters, digits and _");
      if (key == "include") {
        if (value.empty()) throw UserError(where + ": include needs a path");
        if (base_dir.empty()) throw UserError(where + ": include is not allowed here (text that is not a file includes nothing)");
        include((base_dir / value).lexically_normal(), where);
        continue;
      }
      if (section.empty()) throw UserError(where + ": key '" + key + "' is outside any [section]");
      const auto [it, fresh] = seen.emplace(std::make_pair(section, key), line_no);
      if (!fresh) {
        throw UserError(where + ": [" + section + "] " + key + " is already set at line " + std::to_string(it->second) + " of this file");
      }
      entries.push_back({section, key, value, source, line_no});
    }
  }

  void include(const fs::path& path, const std::string& where) {
    std::error_code ec;
    const fs::path canon = fs::weakly_canonical(path, ec);
    const std::string id = ec ? path.string() : canon.string();
    if (std::find(stack_.begin(), stack_.end(), id) != stack_.end()) {
      std::string chain;
      for (const auto& s : stack_) chain += s + " -> ";
      throw UserError(where + ": include cycle: " + chain + id);
    }
    std::string text;
    try {
      text = read_file(path.string());
    } catch (const UserError& e) {
      throw UserError(where + ": cannot include " + e.what());
    }
    stack_.push_back(id);
    parse(text, path.string(), path.parent_path());
    stack_.pop_back();
  }

  void start(const std::string& id) { stack_.push_back(id); }

 private:
  std::vector<std::string> stack_;  // files being read, for cycle detection
};

}  // namespace

std::vector<IniEntry> read_ini_file(const std::string& path) {
  const std::string text = read_file(path);
  Reader r;
  std::error_code ec;
  const fs::path canon = fs::weakly_canonical(fs::path(path), ec);
  r.start(ec ? path : canon.string());
  r.parse(text, path, fs::path(path).parent_path());
  return r.entries;
}

std::vector<IniEntry> parse_ini_text(const std::string& text, const std::string& source, const std::string& base_dir) {
  Reader r;
  r.parse(text, source, fs::path(base_dir));
  return r.entries;
}

}  // namespace paddock::runner
