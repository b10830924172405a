#pragma once
// Private helpers for building error messages inside the core library.

#include <sstream>
#include <string>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace detail {

/// Throws Error("<name> = <value> is out of range; valid: <valid>") unless ok.
template <typename T>
void requireParameter(bool ok, const std::string& name, const T& value, const std::string& valid) {
  if (ok) return;
  std::ostringstream message;
  message << name << " = " << value << " is out of range; valid: " << valid;
  throw Error(message.str());
}

}  // namespace detail
}  // namespace norm2tex
