#pragma once
// The gel's law moved to norm2tex/gel/ (both the renderer and the simulation use it); this
// header keeps code that includes the old path building.
#include "norm2tex/gel/gel_law.hpp"
