#include "sim/runner/ini.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <string_view>
#include <utility>

#include "sim/runner/files.h"

namespace paddock::runner {


namespace {

namespace fs = std::filesystem;

// the blanks trim() drops
bool blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string_view trim_view(std::string_view s) {
  std::size_t b = 0, e = s.size();
  while (b < e && blank(s[b])) ++b;
  while (e > b && blank(s[e - 1])) --e;
  return s.substr(b, e - b);
}

// a ';' or '#' that starts the line or follows whitespace begins a comment
std::string_view strip_comment(std::string_view s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    if ((s[i] == ';' || s[i] == '#') && (i == 0 || s[i - 1] == ' ' || s[i - 1] == '\t')) return s.substr(0, i);
  }
  return s;
}

bool valid_name(std::string_view s) {
  if (s.empty()) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.';
  });
}

// the folder a file's includes are read from: its own, "." for a bare
// name in the current folder (its parent_path() is empty, and an empty base
// is how text that is no file says it may include nothing)
fs::path folder_of(const fs::path& file) {
  const fs::path dir = file.parent_path();
  return dir.empty() ? fs::path(".") : dir;
}

class Reader {
 public:
  std::vector<IniEntry> entries;

  void parse(const std::string& text, const std::string& source, const fs::path& base_dir) {
    std::string section;
    std::map<std::pair<std::string, std::string>, int> seen;  // (section, key) -> line, this file only
    int line_no = 0;
    std::size_t pos = 0;
    // the lines as views of the text: a string is made for what is kept
    // (and for a message), not for every line read
    const std::string_view all(text);
    while (pos <= all.size()) {
      const auto nl = all.find('\n', pos);
      const std::string_view raw = all.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
      pos = nl == std::string_view::npos ? all.size() + 1 : nl + 1;
      ++line_no;
      const auto where = [&source, line_no] { return source + ":" + std::to_string(line_no); };
      const std::string_view line = trim_view(strip_comment(raw));
      if (line.empty()) continue;
      // a section header
      if (line.front() == '[') {
        if (line.back() != ']') throw UserError(where() + ": malformed section header '" + std::string(line) + "', expected [name]");
        section = std::string(trim_view(line.substr(1, line.size() - 2)));
        if (!valid_name(section)) throw UserError(where() + ": bad section name '" + section + "', expected letters, digits and _");
        continue;
      }
      // key = value
      const auto eq = line.find('=');
      if (eq == std::string_view::npos) throw UserError(where() + ": expected 'key = value', '[section]' or a comment, got '" + std::string(line) + "'");
      const std::string key(trim_view(line.substr(0, eq)));
      const std::string value(trim_view(line.substr(eq + 1)));
      if (!valid_name(key)) throw UserError(where() + ": bad key '" + key + "', expected letters, digits and _");
      if (key == "include") {
        if (value.empty()) throw UserError(where() + ": include needs a path");
        if (base_dir.empty()) throw UserError(where() + ": include is not allowed here (text that is not a file includes nothing)");
        include((base_dir / value).lexically_normal(), where());
        continue;
      }
      if (section.empty()) throw UserError(where() + ": key '" + key + "' is outside any [section]");
      const auto [it, fresh] = seen.emplace(std::make_pair(section, key), line_no);
      if (!fresh) {
        throw UserError(where() + ": [" + section + "] " + key + " is already set at line " + std::to_string(it->second) + " of this file");
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
    parse(text, path.string(), folder_of(path));
    stack_.pop_back();
  }

  void start(const std::string& id) { stack_.push_back(id); }

 private:
  std::vector<std::string> stack_;  // files being read, for cycle detection
};

}  // namespace

std::string trim(const std::string& s) { return std::string(trim_view(s)); }

std::vector<IniEntry> read_ini_file(const std::string& path) {
  const std::string text = read_file(path);
  Reader r;
  std::error_code ec;
  const fs::path canon = fs::weakly_canonical(fs::path(path), ec);
  r.start(ec ? path : canon.string());
  r.parse(text, path, folder_of(fs::path(path)));
  return r.entries;
}

std::vector<IniEntry> parse_ini_text(const std::string& text, const std::string& source, const std::string& base_dir) {
  Reader r;
  r.parse(text, source, fs::path(base_dir));
  return r.entries;
}

}  // namespace paddock::runner
