// A small tokenizer shared by PIC's text readers (OBJ, OFF, ASCII STL, ASCII PLY, XYZ).
// It walks a byte range without copying; every step consumes at least one byte or stops, so
// a reader's work is bounded by the file size whatever the content.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace pic::detail {

inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

class TextCursor {
 public:
  TextCursor(const char* begin, const char* end) : p_(begin), end_(end) {}

  bool at_end() const { return p_ >= end_; }
  size_t line() const { return line_; }
  size_t remaining() const { return size_t(end_ - p_); }
  const char* position() const { return p_; }

  /// Next whitespace-separated token on the current line; empty when the line has no more.
  std::string_view token_on_line() {
    while (p_ < end_ && is_blank(*p_)) ++p_;
    const char* s = p_;
    while (p_ < end_ && *p_ != '\n' && !is_blank(*p_)) ++p_;
    return {s, size_t(p_ - s)};
  }

  /// Next token anywhere (crossing line ends); empty only at the end of the text.
  std::string_view token() {
    while (p_ < end_ && (is_blank(*p_) || *p_ == '\n')) {
      if (*p_ == '\n') ++line_;
      ++p_;
    }
    return token_on_line();
  }

  /// The rest of the current line without its end, and moves past the line end.
  std::string_view rest_of_line() {
    const char* s = p_;
    while (p_ < end_ && *p_ != '\n') ++p_;
    std::string_view r(s, size_t(p_ - s));
    if (p_ < end_) {
      ++p_;
      ++line_;
    }
    while (!r.empty() && is_blank(r.back())) r.remove_suffix(1);
    return r;
  }

  void skip_line() { rest_of_line(); }

  /// Moves to the end of the current line, staying on it (for a comment).
  void skip_to_line_end() {
    while (p_ < end_ && *p_ != '\n') ++p_;
  }

 private:
  const char* p_;
  const char* end_;
  size_t line_ = 1;
};

/// Shortens a token for an error message (a "token" may be a megabyte of garbage).
std::string quoted(std::string_view token);

/// Parses a decimal floating-point token (leading '+' allowed; "nan"/"inf" parse and are
/// refused later as non-finite; overflow gives inf). \throws InvalidInput naming `line`.
double parse_double(std::string_view token, size_t line);

/// Parses a decimal integer token. \throws InvalidInput naming `line` (also on overflow).
int64_t parse_int(std::string_view token, size_t line);

}  // namespace pic::detail
