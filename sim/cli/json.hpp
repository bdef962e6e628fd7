#pragma once
// A minimal streaming JSON writer for the CLI's --json output (objects, arrays, numbers,
// strings, booleans). Non-finite numbers become null: JSON has no infinity, and a peak that is
// a Dirac is flagged separately by the caller.
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>

namespace settle::cli {

class JsonWriter {
 public:
  explicit JsonWriter(std::FILE* out) : out_{out} {}

  JsonWriter& begin_object() { return open('{'); }
  JsonWriter& end_object() { return close('}'); }
  JsonWriter& begin_array() { return open('['); }
  JsonWriter& end_array() { return close(']'); }

  JsonWriter& key(std::string_view k) {
    comma();
    write_string(k);
    std::fputc(':', out_);
    after_key_ = true;
    return *this;
  }
  JsonWriter& value(double v) {
    comma();
    if (std::isfinite(v)) {
      std::fprintf(out_, "%.17g", v);
    } else {
      std::fputs("null", out_);
    }
    return *this;
  }
  JsonWriter& value(long long v) {
    comma();
    std::fprintf(out_, "%lld", v);
    return *this;
  }
  JsonWriter& value(bool v) {
    comma();
    std::fputs(v ? "true" : "false", out_);
    return *this;
  }
  JsonWriter& value(std::string_view s) {
    comma();
    write_string(s);
    return *this;
  }
  JsonWriter& value(const char* s) { return value(std::string_view{s}); }
  template <typename V>
  JsonWriter& field(std::string_view k, V v) {
    key(k);
    return value(v);
  }
  void finish() { std::fputc('\n', out_); }

 private:
  JsonWriter& open(char c) {
    comma();
    std::fputc(c, out_);
    first_ = true;
    return *this;
  }
  JsonWriter& close(char c) {
    std::fputc(c, out_);
    first_ = false;
    return *this;
  }
  void comma() {
    if (after_key_) {
      after_key_ = false;
      return;
    }
    if (!first_) std::fputc(',', out_);
    first_ = false;
  }
  void write_string(std::string_view s) {
    std::fputc('"', out_);
    for (char c : s) {
      if (c == '"' || c == '\\') {
        std::fputc('\\', out_);
        std::fputc(c, out_);
      } else if (static_cast<unsigned char>(c) < 0x20) {
        std::fprintf(out_, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
      } else {
        std::fputc(c, out_);
      }
    }
    std::fputc('"', out_);
  }

  std::FILE* out_;
  bool first_{true};
  bool after_key_{false};
};

}  // namespace settle::cli
