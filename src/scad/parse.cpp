// The .csg grammar (what OpenSCAD writes with `-o x.csg`): statements
// `name(key = value, ...) { statement* }` or `name(...);`, values are numbers, true/false,
// undef, "strings" and [vectors]. A small recursive-descent parser; errors name the line.
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "scad/scad_detail.h"

namespace pic::detail::scad {
namespace {

class Parser {
 public:
  explicit Parser(const std::string& text) : s_(text) {}

  std::vector<Node> statements(bool nested) {
    std::vector<Node> out;
    for (;;) {
      skip();
      if (at_end()) {
        if (nested) fail("missing '}'");
        return out;
      }
      if (s_[i_] == '}') {
        if (!nested) fail("unexpected '}'");
        ++i_;
        return out;
      }
      if (s_[i_] == ';') {  // an empty statement
        ++i_;
        continue;
      }
      out.push_back(statement());
    }
  }

 private:
  const std::string& s_;
  size_t i_ = 0;
  int line_ = 1;

  [[noreturn]] void fail(const std::string& what) const {
    throw InvalidInput("line " + std::to_string(line_) + ": " + what);
  }
  bool at_end() const { return i_ >= s_.size(); }
  void skip() {
    while (!at_end()) {
      const char c = s_[i_];
      if (c == '\n') {
        ++line_;
        ++i_;
      } else if (std::isspace(static_cast<unsigned char>(c))) {
        ++i_;
      } else if (c == '/' && i_ + 1 < s_.size() && s_[i_ + 1] == '/') {
        while (!at_end() && s_[i_] != '\n') ++i_;
      } else if (c == '/' && i_ + 1 < s_.size() && s_[i_ + 1] == '*') {
        i_ += 2;
        while (i_ + 1 < s_.size() && !(s_[i_] == '*' && s_[i_ + 1] == '/')) line_ += s_[i_++] == '\n';
        i_ += 2;
      } else {
        return;
      }
    }
  }
  void expect(char c) {
    skip();
    if (at_end() || s_[i_] != c) fail(std::string("expected '") + c + "'" + near());
    ++i_;
  }
  std::string near() const {
    if (at_end()) return " at end of file";
    return " near '" + s_.substr(i_, std::min<size_t>(12, s_.size() - i_)) + "'";
  }
  /// OpenSCAD's modifiers before a statement: `!`, `#`, `%`, `*`.
  static bool modifier(char c) { return c == '!' || c == '#' || c == '%' || c == '*'; }
  static bool ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '$'; }
  std::string identifier() {
    skip();
    const size_t b = i_;
    while (!at_end() && ident_char(s_[i_])) ++i_;
    if (b == i_) fail("expected a name" + near());
    return s_.substr(b, i_ - b);
  }

  Node statement() {
    Node n;
    n.line = line_;
    // OpenSCAD's modifiers: `%` (background) and `*` (disabled) leave the object out of the
    // rendered model (its .csg export keeps them); `#` (highlight) and `!` change display only.
    bool left_out = false;
    while (!at_end() && modifier(s_[i_])) {
      left_out = left_out || s_[i_] == '%' || s_[i_] == '*';
      ++i_;
      skip();
    }
    n.name = identifier();
    expect('(');
    skip();
    int positional = 0;
    if (!at_end() && s_[i_] != ')') {
      for (;;) {
        skip();
        // `key = value` or a bare value.
        const size_t save = i_;
        const int save_line = line_;
        std::string key;
        if (!at_end() && (std::isalpha(static_cast<unsigned char>(s_[i_])) || s_[i_] == '$' || s_[i_] == '_')) {
          key = identifier();
          skip();
          if (at_end() || s_[i_] != '=') {
            i_ = save;
            line_ = save_line;
            key.clear();
          } else {
            ++i_;
          }
        }
        if (key.empty()) key = std::to_string(positional++);
        n.args[key] = value();
        skip();
        if (!at_end() && s_[i_] == ',') {
          ++i_;
          continue;
        }
        break;
      }
    }
    expect(')');
    skip();
    if (at_end()) fail("expected ';' or '{' after " + n.name + "(...)");
    if (s_[i_] == ';') {
      ++i_;
    } else if (s_[i_] == '{') {
      ++i_;
      n.children = statements(true);
    } else if (std::isalpha(static_cast<unsigned char>(s_[i_])) || s_[i_] == '_' || s_[i_] == '$' || modifier(s_[i_])) {
      // One child without braces, as OpenSCAD reads `translate(v) cube(1);`.
      n.children.push_back(statement());
    } else {
      fail("expected ';' or '{' after " + n.name + "(...)" + near());
    }
    if (left_out) {
      n.name = "group";
      n.args.clear();
      n.children.clear();
    }
    return n;
  }

  Value value() {
    skip();
    if (at_end()) fail("expected a value at end of file");
    Value v;
    const char c = s_[i_];
    if (c == '[') {
      ++i_;
      v.kind = Value::Kind::Vector;
      skip();
      if (!at_end() && s_[i_] == ']') {
        ++i_;
        return v;
      }
      for (;;) {
        v.items.push_back(value());
        skip();
        if (at_end()) fail("missing ']'");
        if (s_[i_] == ',') {
          ++i_;
          continue;
        }
        if (s_[i_] == ':') {  // a range [a : b] or [a : s : b] is kept as its numbers
          ++i_;
          continue;
        }
        if (s_[i_] == ']') {
          ++i_;
          return v;
        }
        fail("expected ',' or ']'" + near());
      }
    }
    if (c == '"') {
      ++i_;
      v.kind = Value::Kind::String;
      while (!at_end() && s_[i_] != '"') {
        char ch = s_[i_++];
        if (ch == '\n') ++line_;
        if (ch == '\\' && !at_end()) {
          ch = s_[i_++];
          if (ch == 'n') ch = '\n';
          else if (ch == 't') ch = '\t';
          else if (ch == 'r') ch = '\r';
        }
        v.text += ch;
      }
      if (at_end()) fail("unterminated string");
      ++i_;
      return v;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '-' || c == '+' || c == '.') {
      const char* begin = s_.c_str() + i_;
      char* end = nullptr;
      v.number = std::strtod(begin, &end);
      if (end == begin) fail("bad number" + near());
      i_ += static_cast<size_t>(end - begin);
      v.kind = Value::Kind::Number;
      return v;
    }
    const std::string word = identifier();
    if (word == "true" || word == "false") {
      v.kind = Value::Kind::Bool;
      v.boolean = word == "true";
    } else if (word == "undef") {
      v.kind = Value::Kind::Undef;
    } else if (word == "inf") {
      v.kind = Value::Kind::Number;
      v.number = std::numeric_limits<double>::infinity();
    } else if (word == "nan") {
      v.kind = Value::Kind::Number;
      v.number = std::numeric_limits<double>::quiet_NaN();
    } else {
      fail("unexpected '" + word + "' where a value should be");
    }
    return v;
  }
};

}  // namespace

std::vector<Node> parse(const std::string& text) { return Parser(text).statements(false); }

}  // namespace pic::detail::scad
