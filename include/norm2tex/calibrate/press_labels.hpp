#pragma once
// Known contact circles of ball presses, from a labels CSV that may have been written on another
// machine: `file,centre_x_px,centre_y_px,radius_px`, one press a line.

#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "norm2tex/calibrate/press_detection.hpp"

namespace norm2tex {

/// One line of a labels file.
struct PressLabel {
  std::string name;    ///< the frame's file as the labels write it (any path, any machine)
  PressCircle circle;  ///< pixels of that frame
  int line = 0;        ///< 1-based line in the file, for messages
};

/// Reads labels from `in`; `what` names the source in messages ("labels 'l.csv'"). Lines
/// `file,centre_x_px,centre_y_px,radius_px`: the last three fields are numbers (radius > 0),
/// everything before them is the file name (so a name may hold commas; surrounding quotes and
/// blanks are removed). Line ends LF or CRLF; a UTF-8 byte-order mark, blank lines and lines
/// starting with '#' are skipped; the first other line is a header when a field after its first
/// is not a number. Throws Error naming `what` and the line for any other line that is not a label.
std::vector<PressLabel> parsePressLabels(std::istream& in, const std::string& what);

/// parsePressLabels of the file at `path`; Error naming it when it cannot be read.
std::vector<PressLabel> readPressLabels(const std::string& path);

/// The labels' circles for the presses named `press_names` (their files as given), nullopt for a
/// press no label names. A label names a press when the names are equal, or else when their base
/// names are (after the last '/' or '\'): labels made on another machine carry that machine's
/// paths. Throws Error naming `what` when a label's base name matches two presses (two frames of
/// one name in different folders: name them by their paths), when two labels name one press, or
/// when no label names any press.
std::vector<std::optional<PressCircle>> matchPressLabels(
    const std::vector<PressLabel>& labels, const std::vector<std::string>& press_names,
    const std::string& what);

}  // namespace norm2tex
