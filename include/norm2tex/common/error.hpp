#pragma once

#include <stdexcept>
#include <string>

namespace norm2tex {

/// The one error type of the core library. Messages name the file or parameter at fault and,
/// for parameters, the valid range. Nodes and CLIs catch it and turn it into ROS_ERROR or a
/// non-zero exit; the core never prints and never returns error codes.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace norm2tex
