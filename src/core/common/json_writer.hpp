#pragma once
// A small JSON writer for the reports the tools write. Why not a library: none of the package's
// dependencies writes JSON, the package only writes it (this and the glTF writer's header, which
// shares jsonString) and never reads it, and nlohmann-json would be a new build dependency on
// every supported Debian for about 100 lines. Tests read the output back with yaml-cpp and
// Python's json module (readers independent of this writer).

#include <string>
#include <vector>

namespace norm2tex {

/// A JSON string literal of `text` (UTF-8 passed through; quotes, backslashes and control
/// characters escaped).
std::string jsonString(const std::string& text);

/// A JSON number that reads back as the same double (the shortest of %.15g-%.17g that does), or
/// null for infinity and NaN, which JSON cannot hold.
std::string jsonNumber(double value);

/// Writes one JSON value (objects and arrays nested), indented by two spaces a level. Misuse (a
/// value without a key in an object, a key in an array, unbalanced ends, text() before the
/// value is complete) throws Error: it is a bug of the caller, found by its tests.
class JsonWriter {
 public:
  JsonWriter& beginObject();
  JsonWriter& endObject();
  JsonWriter& beginArray();
  JsonWriter& endArray();
  /// The name of the next value, inside an object.
  JsonWriter& key(const std::string& name);
  JsonWriter& value(const std::string& text);
  JsonWriter& value(const char* text);
  JsonWriter& value(double number);  ///< see jsonNumber
  JsonWriter& value(int number);
  JsonWriter& value(bool flag);
  /// The complete text, ending with a newline.
  std::string text() const;

 private:
  struct Level {
    bool is_object = false;
    int members = 0;
    bool awaiting_value = false;  ///< a key was written, its value not yet
  };
  void beforeValue();
  void newLine();
  void end(bool is_object, char bracket);
  std::string out_;
  std::vector<Level> levels_;
};

}  // namespace norm2tex
