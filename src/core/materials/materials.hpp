#pragma once
// Factories of the concrete materials (one .cpp each), used by makeMaterial().

#include <memory>

#include "norm2tex/materials/procedural_material.hpp"

namespace norm2tex {
namespace materials {

std::unique_ptr<ProceduralMaterial> makeWood();
std::unique_ptr<ProceduralMaterial> makeFabric();
std::unique_ptr<ProceduralMaterial> makeRock();
std::unique_ptr<ProceduralMaterial> makeSmooth();
std::unique_ptr<ProceduralMaterial> makePrint3d();

/// Degrees to radians.
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

}  // namespace materials
}  // namespace norm2tex
