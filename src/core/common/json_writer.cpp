#include "common/json_writer.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

std::string jsonString(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escape[8];
      std::snprintf(escape, sizeof(escape), "\\u%04x", static_cast<unsigned>(c));
      out += escape;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string jsonNumber(double value) {
  if (!std::isfinite(value)) return "null";
  char text[32];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(text, sizeof(text), "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value) break;
  }
  return text;
}

void JsonWriter::newLine() {
  out_ += '\n';
  out_.append(2 * levels_.size(), ' ');
}

void JsonWriter::beforeValue() {
  if (levels_.empty()) {
    if (!out_.empty()) throw Error("JsonWriter: a second top-level value");
    return;
  }
  Level& level = levels_.back();
  if (level.is_object) {
    if (!level.awaiting_value) throw Error("JsonWriter: a value in an object without a key");
    level.awaiting_value = false;
    return;
  }
  if (level.members++ > 0) out_ += ',';
  newLine();
}

JsonWriter& JsonWriter::key(const std::string& name) {
  if (levels_.empty() || !levels_.back().is_object || levels_.back().awaiting_value) {
    throw Error("JsonWriter: key '" + name + "' outside an object or after another key");
  }
  Level& level = levels_.back();
  if (level.members++ > 0) out_ += ',';
  newLine();
  out_ += jsonString(name) + ": ";
  level.awaiting_value = true;
  return *this;
}

JsonWriter& JsonWriter::beginObject() {
  beforeValue();
  out_ += '{';
  levels_.push_back({true, 0, false});
  return *this;
}

JsonWriter& JsonWriter::beginArray() {
  beforeValue();
  out_ += '[';
  levels_.push_back({false, 0, false});
  return *this;
}

void JsonWriter::end(bool is_object, char bracket) {
  if (levels_.empty() || levels_.back().is_object != is_object || levels_.back().awaiting_value) {
    throw Error(std::string("JsonWriter: '") + bracket + "' does not close what is open");
  }
  const bool had_members = levels_.back().members > 0;
  levels_.pop_back();
  if (had_members) newLine();
  out_ += bracket;
}

JsonWriter& JsonWriter::endObject() {
  end(true, '}');
  return *this;
}

JsonWriter& JsonWriter::endArray() {
  end(false, ']');
  return *this;
}

JsonWriter& JsonWriter::value(const std::string& text) {
  beforeValue();
  out_ += jsonString(text);
  return *this;
}

JsonWriter& JsonWriter::value(const char* text) { return value(std::string(text)); }

JsonWriter& JsonWriter::value(double number) {
  beforeValue();
  out_ += jsonNumber(number);
  return *this;
}

JsonWriter& JsonWriter::value(int number) {
  beforeValue();
  out_ += std::to_string(number);
  return *this;
}

JsonWriter& JsonWriter::value(bool flag) {
  beforeValue();
  out_ += flag ? "true" : "false";
  return *this;
}

std::string JsonWriter::text() const {
  if (out_.empty() || !levels_.empty()) throw Error("JsonWriter: the value is not complete");
  return out_ + '\n';
}

}  // namespace norm2tex
