// Labels CSV of ball presses (see norm2tex/calibrate/press_labels.hpp).
#include "norm2tex/calibrate/press_labels.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

std::string trim(const std::string& text) {
  const char* const blanks = " \t\r\n";
  const size_t begin = text.find_first_not_of(blanks);
  if (begin == std::string::npos) return {};
  return text.substr(begin, text.find_last_not_of(blanks) - begin + 1);
}

std::string unquote(std::string text) {
  text = trim(text);
  if (text.size() >= 2 && text.front() == '"' && text.back() == '"') {
    text = text.substr(1, text.size() - 2);
  }
  return text;
}

std::optional<double> number(const std::string& field) {
  const std::string text = trim(field);
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

// The last component of a path written on any system ("C:\data\f.png", "/home/x/f.png").
std::string baseName(const std::string& path) {
  const size_t slash = path.find_last_of("/\\");
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

std::vector<PressLabel> parsePressLabels(std::istream& in, const std::string& what) {
  std::vector<PressLabel> labels;
  std::string line;
  bool first = true;
  for (int number_of_line = 1; std::getline(in, line); ++number_of_line) {
    if (number_of_line == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // BOM
    const std::string content = trim(line);
    if (content.empty() || content[0] == '#') continue;
    const bool header_allowed = first;
    first = false;
    std::vector<std::string> fields;
    std::istringstream split(content);
    for (std::string field; std::getline(split, field, ',');) fields.push_back(field);
    std::optional<double> x, y, r;
    if (fields.size() >= 4) {
      x = number(fields[fields.size() - 3]);
      y = number(fields[fields.size() - 2]);
      r = number(fields[fields.size() - 1]);
    }
    if (!x || !y || !r) {
      // A header ("file,centre_x_px,centre_y_px,radius_px" or similar): a field after the name
      // that is not a number. A line of numbers too few is a mistake, even first.
      bool words = false;
      for (size_t i = 1; i < fields.size(); ++i) words = words || !number(fields[i]);
      if (header_allowed && words) continue;
      throw Error(what + " line " + std::to_string(number_of_line) +
                  ": expected 'file,centre_x_px,centre_y_px,radius_px' (numbers), got '" + content +
                  "'");
    }
    std::string name = fields[0];
    for (size_t i = 1; i + 3 < fields.size(); ++i) name += "," + fields[i];
    name = unquote(name);
    if (name.empty() || !(*r > 0.0)) {
      throw Error(what + " line " + std::to_string(number_of_line) +
                  (name.empty() ? ": the file name is empty" : ": radius_px must be > 0"));
    }
    labels.push_back(PressLabel{name, PressCircle{{*x, *y}, *r}, number_of_line});
  }
  return labels;
}

std::vector<PressLabel> readPressLabels(const std::string& path) {
  const std::string what = "labels '" + path + "'";
  std::ifstream file(path, std::ios::binary);
  if (!file) throw Error(what + " cannot be read");
  std::vector<PressLabel> labels = parsePressLabels(file, what);
  if (file.bad()) throw Error(what + " cannot be read");
  return labels;
}

std::vector<std::optional<PressCircle>> matchPressLabels(
    const std::vector<PressLabel>& labels, const std::vector<std::string>& press_names,
    const std::string& what) {
  std::vector<std::optional<PressCircle>> circles(press_names.size());
  std::vector<const PressLabel*> labelled_by(press_names.size(), nullptr);
  for (const PressLabel& label : labels) {
    // The press the label names: by its name as given, else by base name, unambiguously.
    std::vector<size_t> matches;
    for (size_t i = 0; i < press_names.size(); ++i) {
      if (press_names[i] == label.name) matches = {i};
    }
    if (matches.empty()) {
      const std::string base = baseName(label.name);
      for (size_t i = 0; i < press_names.size(); ++i) {
        if (baseName(press_names[i]) == base) matches.push_back(i);
      }
    }
    if (matches.size() > 1) {
      throw Error(what + " line " + std::to_string(label.line) + ": '" + label.name +
                  "' matches presses '" + press_names[matches[0]] + "' and '" +
                  press_names[matches[1]] +
                  "' by base name; give frames unique file names or label them by the paths "
                  "given to --presses");
    }
    if (matches.empty()) continue;  // a frame not among these presses
    const size_t press = matches.front();
    if (labelled_by[press] != nullptr) {
      throw Error(what + " lines " + std::to_string(labelled_by[press]->line) + " and " +
                  std::to_string(label.line) + " both label press '" + press_names[press] + "'");
    }
    labelled_by[press] = &label;
    circles[press] = label.circle;
  }
  bool any = false;
  for (const auto& circle : circles) any = any || circle.has_value();
  if (!any && !press_names.empty()) {
    throw Error(what + " name none of the " + std::to_string(press_names.size()) +
                " presses (matched by file name or base name, e.g. '" +
                baseName(press_names.front()) + "')");
  }
  return circles;
}

}  // namespace norm2tex
