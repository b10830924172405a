// Bindings of the renderer's side: sensor model, meshes, textures, materials, TactileRenderer.

#include <memory>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "norm2tex/calibrate/image_metrics.hpp"
#include "norm2tex/calibrate/ridge_contrast.hpp"
#include "norm2tex/calibrate/sensor_calibration.hpp"
#include <opencv2/imgcodecs.hpp>

#include "norm2tex/common/image_io.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/materials/procedural_material.hpp"
#include "norm2tex/mesh/object_mesh.hpp"
#include "norm2tex/render/block_mean.hpp"
#include "norm2tex/render/object_texture.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/texture/height_atlas_baker.hpp"
#include "norm2tex/texture/normal_map.hpp"
#include "numpy_conversions.hpp"

namespace norm2tex {
namespace python {
namespace {

// An 8-bit image from numpy: (rows, cols) grey or (rows, cols, 3) bgr.
cv::Mat imageFromNumpy(const py::handle& handle, const std::string& what) {
  const py::array array = py::array::ensure(handle);
  const bool grey = array && array.ndim() == 2;
  return fromNumpy(handle, grey ? CV_8UC1 : CV_8UC3, what);
}

// One press's frame comparison, keyed as in norm2tex_calibrate's --json report.
py::dict pressFrameDict(const PressFrameComparison& press) {
  py::dict out;
  out["image"] = press.name;
  out["index"] = press.index;
  out["held_out"] = press.held_out;
  out["labelled"] = press.labelled;
  out["centre_px"] = py::make_tuple(press.circle.centre_px.x, press.circle.centre_px.y);
  out["radius_px"] = press.circle.radius_px;
  out["contact_radius_px"] = press.contact_radius_px;
  out["depth_mm"] = press.depth_mm;
  out["ssim"] = press.similarity.ssim;
  out["contact_ssim"] = press.similarity.ssim_in_mask;
  out["psnr_db"] = press.similarity.psnr_db;
  out["mean_abs_diff"] = press.similarity.mean_abs_diff;
  py::dict bare;
  bare["ssim"] = press.bare_background.ssim;
  bare["contact_ssim"] = press.bare_background.ssim_in_mask;
  bare["psnr_db"] = press.bare_background.psnr_db;
  bare["mean_abs_diff"] = press.bare_background.mean_abs_diff;
  out["bare_background"] = bare;
  return out;
}

py::list pressFrameList(const std::vector<PressFrameComparison>& presses) {
  py::list out;
  for (const PressFrameComparison& press : presses) out.append(pressFrameDict(press));
  return out;
}

using Release = py::call_guard<py::gil_scoped_release>;

/// One rendered frame, copied out of the renderer's reused buffers.
struct RenderedFrame {
  py::array image;         // (rows, cols, 3) uint8, bgr8
  py::array depth;         // (rows, cols) float32, metres
  py::array contact_mask;  // (rows, cols) uint8, 255 in contact
  bool textured = false;
  py::object shear = py::none();          // (rows, cols, 2) float32, metres, or None
  py::object markers = py::none();        // dict of (n, 2) float32 arrays, or None
  py::object slip_fraction = py::none();  // float, or None
};

py::array_t<float> pointsToNumpy(const std::vector<Marker>& markers,
                                 cv::Point2f Marker::*field) {
  py::array_t<float> out({static_cast<Py_ssize_t>(markers.size()), Py_ssize_t{2}});
  auto a = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < markers.size(); ++i) {
    a(i, 0) = (markers[i].*field).x;
    a(i, 1) = (markers[i].*field).y;
  }
  return out;
}

RenderedFrame copyFrame(const TactileFrame& frame, bool sheared) {
  RenderedFrame out;
  out.image = toNumpy(frame.image);
  out.depth = toNumpy(frame.depthMetres());
  out.contact_mask = toNumpy(frame.contact_mask);
  out.textured = frame.textured;
  if (frame.shear) {
    if (sheared) {
      out.shear = toNumpy(frame.shear->displacementMetres(frame.image.size()));
      out.slip_fraction = py::float_(frame.shear->slipFraction());
    }
    if (!frame.shear->markers.empty()) {
      py::dict markers;
      markers["rest_px"] = pointsToNumpy(frame.shear->markers, &Marker::rest_px);
      markers["current_px"] = pointsToNumpy(frame.shear->markers, &Marker::current_px);
      markers["displacement_mm"] = pointsToNumpy(frame.shear->markers, &Marker::displacement_mm);
      out.markers = markers;
    }
  }
  return out;
}

py::array_t<float> vectorsToNumpy(const std::vector<Eigen::Vector3f>& v) {
  py::array_t<float> out({static_cast<Py_ssize_t>(v.size()), Py_ssize_t{3}});
  auto a = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int k = 0; k < 3; ++k) a(i, k) = v[i][k];
  return out;
}

/// A texture for `mesh` (a copy: unwrapped when it has no UVs): atlas, the mesh it is for, and
/// the beta it comes with.
py::tuple textureFor(const TextureSource& source, const TexturedMesh& mesh) {
  auto copy = std::make_shared<TexturedMesh>(mesh);
  ObjectTexture texture;
  {
    py::gil_scoped_release release;
    texture = loadObjectTexture(source, *copy);
  }
  return py::make_tuple(std::const_pointer_cast<HeightAtlas>(texture.atlas), copy,
                        texture.beta_mm, texture.description);
}

}  // namespace

void bindRender(py::module& m) {
  py::class_<SensorModel>(m, "SensorModel",
                          "Everything about one DIGIT that the renderer needs (config/digit.yaml). "
                          "Gel frame: origin at the centre of the undeformed gel surface, +x image "
                          "right, +y image down, +z out of the gel towards the object.")
      .def(py::init([](bool vga) { return makeDigitSensorModel(vga); }), py::arg("vga") = false,
           "The default DIGIT at QVGA (320 x 240), or VGA (640 x 480) with vga=True.")
      .def_static("load", &loadSensorModel, py::arg("yaml_path"),
                  "Loads a sensor yaml (config/digit.yaml); raises norm2tex.Error naming the "
                  "file and key at fault.")
      .def("save", [](const SensorModel& s, const std::string& path) { saveSensorModel(s, path); },
           py::arg("yaml_path"), "Writes the model as a sensor yaml that load() reads back.")
      .def_readwrite("rows", &SensorModel::rows, "image height, pixels")
      .def_readwrite("cols", &SensorModel::cols, "image width, pixels")
      .def_readwrite("mm_per_pixel", &SensorModel::mm_per_pixel, "gel mm per pixel at the gel")
      .def_readwrite("gel_thickness_mm", &SensorModel::gel_thickness_mm, "indentation limit, mm")
      .def_readwrite("gel_pad_width_mm", &SensorModel::gel_pad_width_mm, "physical pad, mm")
      .def_readwrite("gel_pad_height_mm", &SensorModel::gel_pad_height_mm, "physical pad, mm")
      .def_property(
          "gel_final_sigma_mm", [](const SensorModel& s) { return s.gel.final_sigma_mm; },
          [](SensorModel& s, double sigma) { s.gel.final_sigma_mm = sigma; },
          "the gel model's last blur, mm (gel_model.final_sigma_mm)")
      .def_property(
          "conformity_enabled", [](const SensorModel& s) { return s.conformity.enabled; },
          [](SensorModel& s, bool on) { s.conformity.enabled = on; },
          "pressure-dependent conformity of the gel to the texture (off: the fixed-depth overlay)")
      .def_property(
          "contact_modulus_mpa",
          [](const SensorModel& s) { return s.conformity.contact_modulus_mpa; },
          [](SensorModel& s, double e) { s.conformity.contact_modulus_mpa = e; },
          "the gel's contact modulus E*, MPa (the conformity model's)")
      .def_property(
          "coating_length_mm",
          [](const SensorModel& s) { return s.conformity.coating_length_mm; },
          [](SensorModel& s, double l) { s.conformity.coating_length_mm = l; },
          "the coating's bending length, mm: relief of wavelength L needs (1 + (2 pi l / L)^3) "
          "times Johnson's pressure (0: no coating)")
      .def_property(
          "slope_saturation",
          [](const SensorModel& s) { return s.shading.slope_saturation; },
          [](SensorModel& s, double v) { s.shading.slope_saturation = v; },
          "the slope at which the calibrated shading's slope features saturate (0: none)")
      .def_property(
          "markers_enabled", [](const SensorModel& s) { return s.markers.enabled; },
          [](SensorModel& s, bool on) { s.markers.enabled = on; },
          "whether the gel carries the printed marker grid (the yaml's markers section)")
      .def_property_readonly(
          "marker_grid", [](const SensorModel& s) { return py::make_tuple(s.markers.rows, s.markers.cols); },
          "(rows, cols) of the marker grid (the yaml's markers section, drawn when enabled)")
      .def_property(
          "shear_modulus_mpa", [](const SensorModel& s) { return s.shear.shear_modulus_mpa; },
          [](SensorModel& s, double g) { s.shear.shear_modulus_mpa = g; },
          "the gel's shear modulus G, MPa (how far a shear load moves its surface)")
      .def_readwrite("background_image", &SensorModel::background_image,
                     "no-contact frame (bgr image file); empty: the synthetic background")
      .def_property_readonly(
          "shading_response_bgr",
          [](const SensorModel& s) {
            py::array_t<double> out({Py_ssize_t{3}, Py_ssize_t{kShadingFeatureCount}});
            auto a = out.mutable_unchecked<2>();
            for (int c = 0; c < 3; ++c)
              for (int k = 0; k < kShadingFeatureCount; ++k) a(c, k) = s.shading.response_bgr[c][k];
            return out;
          },
          "(3, 24) the calibrated shading response: grey levels per unit of each feature, rows B, G, R")
      .def_property_readonly("noise_sigma_bgr", [](const SensorModel& s) {
            return py::make_tuple(s.noise.sigma_bgr[0], s.noise.sigma_bgr[1], s.noise.sigma_bgr[2]);
          }, "pixel noise, grey levels, per channel B, G, R")
      .def("validate", [](const SensorModel& s) { validate(s); },
           "Raises norm2tex.Error naming the first field out of range.")
      .def("__repr__", [](const SensorModel& s) {
        return "<SensorModel " + std::to_string(s.rows) + "x" + std::to_string(s.cols) + ", " +
               std::to_string(s.mm_per_pixel) + " mm/px>";
      });

  py::class_<TexturedMesh, std::shared_ptr<TexturedMesh>>(
      m, "TexturedMesh", "A triangle mesh with optional UVs, in metres (the object frame).")
      .def(py::init([](py::array_t<float, py::array::c_style | py::array::forcecast> vertices,
                       py::array_t<int, py::array::c_style | py::array::forcecast> triangles) {
             if (vertices.ndim() != 2 || vertices.shape(1) != 3 || triangles.ndim() != 2 ||
                 triangles.shape(1) != 3) {
               throw py::value_error("vertices must be (N, 3) and triangles (M, 3)");
             }
             std::vector<Eigen::Vector3f> v(vertices.shape(0));
             std::vector<Eigen::Vector3i> t(triangles.shape(0));
             for (Py_ssize_t i = 0; i < vertices.shape(0); ++i)
               v[i] = {vertices.at(i, 0), vertices.at(i, 1), vertices.at(i, 2)};
             for (Py_ssize_t i = 0; i < triangles.shape(0); ++i)
               t[i] = {triangles.at(i, 0), triangles.at(i, 1), triangles.at(i, 2)};
             return std::make_shared<TexturedMesh>(std::move(v), std::move(t));
           }),
           py::arg("vertices"), py::arg("triangles"),
           "A mesh from (N, 3) vertices in metres and (M, 3) vertex indices, wound outwards; "
           "no UVs (a material unwraps it).")
      .def_property_readonly("vertices",
                             [](const TexturedMesh& mesh) { return vectorsToNumpy(mesh.vertices()); },
                             "(N, 3) float32, metres")
      .def_property_readonly("triangles",
                             [](const TexturedMesh& mesh) {
                               py::array_t<int> out({static_cast<Py_ssize_t>(mesh.triangles().size()),
                                                     Py_ssize_t{3}});
                               auto a = out.mutable_unchecked<2>();
                               for (std::size_t i = 0; i < mesh.triangles().size(); ++i)
                                 for (int k = 0; k < 3; ++k) a(i, k) = mesh.triangles()[i][k];
                               return out;
                             },
                             "(M, 3) int32 vertex indices")
      .def_property_readonly("has_uvs", &TexturedMesh::hasUvs)
      .def_property_readonly("bounds",
                             [](const TexturedMesh& mesh) {
                               const Eigen::Vector3d lo = mesh.bounds().min().cast<double>();
                               const Eigen::Vector3d hi = mesh.bounds().max().cast<double>();
                               return py::make_tuple(lo, hi);
                             },
                             "(min xyz, max xyz), metres");

  m.def(
      "load_object_mesh",
      [](const std::string& spec, double scale) {
        ObjectMesh object;
        {
          py::gil_scoped_release release;
          object = loadObjectMesh(spec, scale);
        }
        py::dict out;
        out["mesh"] = std::make_shared<TexturedMesh>(std::move(object.mesh));
        out["shape"] = std::string(shapeName(object.shape));
        out["radius_m"] = object.radius_m;
        out["half_length_m"] = object.half_length_m;
        out["axis"] = object.axis;
        return out;
      },
      py::arg("spec"), py::arg("scale") = 1.0,
      "Loads an object: a mesh file (OBJ, STL, PLY, DAE, glTF/GLB; `scale` converts its units to "
      "metres) or a primitive in millimetres, 'box:<x>x<y>x<z>' or 'sphere:<r>'. Returns a dict: "
      "mesh (TexturedMesh), shape ('mesh', 'box', 'sphere', 'cylinder', 'capsule'), radius_m, "
      "half_length_m, axis. Raises norm2tex.Error naming the file.");

  py::class_<HeightAtlas, std::shared_ptr<HeightAtlas>>(
      m, "HeightAtlas",
      "H_global: the baked height map of a texture over the UV square, with its validity mask. "
      "Row 0 is v = 1 (OpenGL/glTF UVs). Heights are normalised (a material: [-1, 1]) or, at "
      "physical scale, millimetres.")
      .def(py::init([](const py::array& heights, const py::object& valid) {
             cv::Mat1f h = fromNumpy(heights, CV_32FC1, "heights");
             cv::Mat1b v = valid.is_none() ? cv::Mat1b(h.size(), 255)
                                           : cv::Mat1b(fromNumpy(valid, CV_8UC1, "valid"));
             return std::make_shared<HeightAtlas>(h, v);
           }),
           py::arg("heights"), py::arg("valid") = py::none(),
           "From (rows, cols) float32 heights and an optional uint8 mask (non-zero = valid; "
           "NaN heights are invalid). Copies both.")
      .def_property_readonly("heights", [](const HeightAtlas& a) { return toNumpy(a.heights()); },
                             "(rows, cols) float32 (0 where invalid)")
      .def_property_readonly("valid", [](const HeightAtlas& a) { return toNumpy(a.valid()); },
                             "(rows, cols) uint8, 255 where valid")
      .def_property_readonly("shape", [](const HeightAtlas& a) { return py::make_tuple(a.rows(), a.cols()); })
      .def_property_readonly("island_count", &HeightAtlas::islandCount)
      .def("sample", [](const HeightAtlas& a, double u, double v) { return a.sample(u, v); },
           py::arg("u"), py::arg("v"), "H_global at (u, v), bilinear within a UV island; 0 if invalid.");

  m.def(
      "bake_normal_map",
      [](const std::string& path, const std::string& convention, double mm_per_texel) {
        NormalMapOptions map_options;
        map_options.convention = parseNormalConvention(convention);
        BakeOptions options;
        options.mm_per_texel = mm_per_texel;
        py::gil_scoped_release release;
        return std::make_shared<HeightAtlas>(
            bakeHeightAtlas(NormalMap::load(path, map_options), options));
      },
      py::arg("path"), py::arg("convention") = "opengl", py::arg("mm_per_texel") = 0.0,
      "Integrates a UV normal map (PNG/JPEG/TIFF; convention 'opengl' (+Y up) or 'directx') "
      "into H_global, as norm2tex_bake does (no disk cache). mm_per_texel > 0 sets the relief "
      "filter's scale in mm; 0 uses its texel default.");

  m.def(
      "load_texture",
      [](const TexturedMesh& mesh, const std::string& normal_map, const std::string& atlas,
         const std::string& convention) {
        TextureSource source;
        source.normal_map = normal_map;
        source.atlas = atlas;
        source.convention = parseNormalConvention(convention);
        return textureFor(source, mesh);
      },
      py::arg("mesh"), py::arg("normal_map") = "", py::arg("atlas") = "",
      py::arg("convention") = "opengl",
      "The texture the ROS renderer would use for `mesh`: a normal map (baked through the disk "
      "cache), a baked atlas (float TIFF), or with neither the mesh's own normal texture. "
      "Returns (HeightAtlas or None, TexturedMesh it is for, beta_mm it comes with (0: none), "
      "description).");

  m.def("material_names", &materialNames, "The procedural materials: wood, fabric, rock, ...");
  py::class_<MaterialConfig>(m, "MaterialConfig", "config/materials/<name>.yaml")
      .def_static("load", &loadMaterialConfig, py::arg("yaml_path"))
      .def_readonly("name", &MaterialConfig::name)
      .def_readonly("beta_mm", &MaterialConfig::beta_mm, "texture depth, mm")
      .def_readonly("friction", &MaterialConfig::friction, "Coulomb coefficient against the gel")
      .def_readonly("mm_per_texel", &MaterialConfig::mm_per_texel)
      .def_readonly("size", &MaterialConfig::size)
      .def_readonly("variant_count", &MaterialConfig::variant_count);
  m.def(
      "material_texture",
      [](const std::string& material_config, const TexturedMesh& mesh, int variant,
         std::uint64_t seed) {
        TextureSource source;
        source.material_config = material_config;
        source.variant = variant;
        source.seed = seed;
        return textureFor(source, mesh);
      },
      py::arg("material_config"), py::arg("mesh"), py::arg("variant") = 0, py::arg("seed") = 0,
      "Generates variant `variant` (0 = the yaml's own values) of a material for the mesh's UV "
      "layout (a mesh without UVs is unwrapped): returns (HeightAtlas, TexturedMesh it is for "
      "(render this one), the material's beta_mm, description). ~0.5 s for a 1024^2 atlas.");

  m.def(
      "read_image",
      [](const std::string& path) {
        return toNumpy(readImage(path, cv::IMREAD_COLOR, "image"));
      },
      py::arg("path"),
      "Reads an image file as the package's tools do (OpenCV's decoders): (rows, cols, 3) uint8 "
      "bgr. Raises norm2tex.Error naming the file.");

  m.def(
      "block_mean",
      [](const py::array& images, int factor, const py::object& background) {
        // Views of the caller's arrays (no copy in): this runs on every environment step.
        using Bytes = py::array_t<std::uint8_t, py::array::c_style>;
        const Bytes in = Bytes::ensure(images);
        if (!in || !images.dtype().is(py::dtype::of<std::uint8_t>()) ||
            (in.ndim() != 3 && in.ndim() != 4) || in.shape(in.ndim() - 1) != 3) {
          throw py::value_error("block_mean: images must be uint8 of shape (rows, cols, 3) or "
                                "(N, rows, cols, 3)");
        }
        const bool batched = in.ndim() == 4;
        const Py_ssize_t n = batched ? in.shape(0) : 1;
        const int rows = static_cast<int>(in.shape(batched ? 1 : 0));
        const int cols = static_cast<int>(in.shape(batched ? 2 : 1));
        Bytes bg;
        cv::Mat3b bg_view;
        if (!background.is_none()) {
          bg = Bytes::ensure(background);
          if (!bg || !py::array(background).dtype().is(py::dtype::of<std::uint8_t>()) ||
              bg.ndim() != 3 || bg.shape(0) != rows || bg.shape(1) != cols || bg.shape(2) != 3) {
            throw py::value_error("block_mean: background must be uint8 of shape (rows, cols, 3), "
                                  "the images' rows and cols");
          }
          bg_view = cv::Mat3b(rows, cols, const_cast<cv::Vec3b*>(
                                              reinterpret_cast<const cv::Vec3b*>(bg.data())));
        }
        if (factor < 1 || factor > rows || factor > cols) {
          throw py::value_error("block_mean: factor " + std::to_string(factor) +
                                "; valid: 1 .. the smaller of rows and cols");
        }
        std::vector<Py_ssize_t> shape = {rows / factor, cols / factor, 3};
        if (batched) shape.insert(shape.begin(), n);
        py::array_t<float> out(shape);
        const std::size_t in_step = static_cast<std::size_t>(rows) * cols;
        const std::size_t out_step = static_cast<std::size_t>(rows / factor) * (cols / factor);
        const auto* src = reinterpret_cast<const cv::Vec3b*>(in.data());
        auto* dst = reinterpret_cast<cv::Vec3f*>(out.mutable_data());
        {
          py::gil_scoped_release release;
          for (Py_ssize_t i = 0; i < n; ++i) {
            const cv::Mat3b image(rows, cols, const_cast<cv::Vec3b*>(src + i * in_step));
            cv::Mat3f block(rows / factor, cols / factor, dst + i * out_step);
            blockMean(image, factor, bg_view, block);  // writes in place: the size matches
          }
        }
        return out;
      },
      py::arg("images"), py::arg("factor"), py::arg("background") = py::none(),
      "float32 mean of every factor x factor block of bgr8 images ((rows, cols, 3) or (N, rows, "
      "cols, 3)), minus the background's when given; rows and cols past the last whole block are "
      "dropped. Equals numpy's blocks.mean(axis=(2, 4), dtype=float32) of the same crop, ~20x "
      "faster: what the environments' downscale and diff images are made with.");

  m.def(
      "measure_ridge_contrast",
      [](const py::handle& frame, const py::handle& background, std::array<int, 4> box,
         std::optional<std::array<int, 4>> noise_box, double fine_sigma_px,
         double coarse_sigma_px, double normal_angle_rad) {
        RidgeContrastOptions options;
        options.fine_sigma_px = fine_sigma_px;
        options.coarse_sigma_px = coarse_sigma_px;
        options.normal_angle_rad = normal_angle_rad;
        const auto rect = [](const std::array<int, 4>& r) { return cv::Rect(r[0], r[1], r[2], r[3]); };
        const RidgeContrast c = measureRidgeContrast(
            cv::Mat3b(fromNumpy(frame, CV_8UC3, "frame")),
            cv::Mat3b(fromNumpy(background, CV_8UC3, "background")), rect(box),
            noise_box ? rect(*noise_box) : cv::Rect(), options);
        py::dict out;
        out["raw"] = c.raw;
        out["noise"] = c.noise;
        out["contrast"] = c.contrast;
        return out;
      },
      py::arg("frame"), py::arg("background"), py::arg("box"), py::arg("noise_box") = py::none(),
      py::arg("fine_sigma_px") = 1.5, py::arg("coarse_sigma_px") = 6.0,
      py::arg("normal_angle_rad") = 0.0,
      "The ridges' contrast of a bgr8 frame against its background (grey levels): the RMS in box "
      "(x, y, width, height) of a difference of Gaussians across the ridges (sigmas in px, along "
      "the normal at normal_angle_rad from +x towards +y), B, G, R in quadrature, less the same "
      "in noise_box (outside the contact) in quadrature: dict raw, noise, contrast.");

  m.def(
      "calibrate_sensor",
      [](const SensorModel& base, const py::list& backgrounds, const py::list& presses,
         double ball_diameter_mm, std::optional<double> mm_per_pixel, double holdout_fraction) {
        CalibrationInput input;
        for (std::size_t i = 0; i < backgrounds.size(); ++i) {
          input.backgrounds.push_back(
              {"background " + std::to_string(i), fromNumpy(backgrounds[i], CV_8UC3, "background")});
        }
        for (std::size_t i = 0; i < presses.size(); ++i) {
          input.presses.push_back(
              {"press " + std::to_string(i), fromNumpy(presses[i], CV_8UC3, "press")});
        }
        input.ball_diameter_mm = ball_diameter_mm;
        input.mm_per_pixel = mm_per_pixel;
        CalibrationOptions options;
        options.holdout_fraction = holdout_fraction;
        CalibrationResult result;
        {
          py::gil_scoped_release release;
          result = calibrateSensor(base, input, options);
        }
        py::dict out;
        out["model"] = result.model;
        out["background"] = toNumpy(result.background);
        out["training_presses"] = result.training_presses;
        out["held_out_presses"] = result.held_out.presses;
        out["variance_explained"] = result.held_out.variance_explained;
        out["real_contact_mean"] = result.held_out.real_contact_mean;
        out["sim_contact_mean"] = result.held_out.sim_contact_mean;
        out["side_error_deg"] = py::make_tuple(result.held_out.side_error_deg[0],
                                               result.held_out.side_error_deg[1],
                                               result.held_out.side_error_deg[2]);
        out["held_out_frames"] = pressFrameList(result.held_out_frames);
        out["training_frames"] = pressFrameList(result.training_frames);
        const ImageSimilarity medians = medianSimilarity(result.held_out_frames);
        out["median_ssim"] = medians.ssim;
        out["median_contact_ssim"] = medians.ssim_in_mask;
        out["median_psnr_db"] = medians.psnr_db;
        out["median_mean_abs_diff"] = medians.mean_abs_diff;
        return out;
      },
      py::arg("base"), py::arg("backgrounds"), py::arg("presses"), py::arg("ball_diameter_mm"),
      py::arg("mm_per_pixel") = py::none(), py::arg("holdout_fraction") = 0.3,
      "Fits a SensorModel to your DIGIT, as norm2tex_calibrate: no-contact frames and ball "
      "presses (lists of (rows, cols, 3) uint8 bgr of base's size), the ball's diameter (mm) and "
      "the scale (mm per pixel; None: fitted). Returns a dict: model (SensorModel; its "
      "background_image unset), background (the mean no-contact frame), training_presses, "
      "held_out_presses and how well the model reproduces those: variance_explained, "
      "real_contact_mean / sim_contact_mean (grey levels), side_error_deg (B, G, R); each press's "
      "render against its real frame in held_out_frames and training_frames (dicts keyed as "
      "norm2tex_calibrate's --json presses: ssim, contact_ssim, psnr_db, mean_abs_diff, circle, "
      "depth_mm, bare_background: the background alone against the frame, ...), and the "
      "held-out medians median_ssim, median_contact_ssim, median_psnr_db, "
      "median_mean_abs_diff.");

  m.def(
      "compare_images",
      [](const py::handle& a, const py::handle& b, const py::handle& mask) {
        const cv::Mat image_a = imageFromNumpy(a, "a"), image_b = imageFromNumpy(b, "b");
        const cv::Mat mask_image = mask.is_none() ? cv::Mat() : fromNumpy(mask, CV_8UC1, "mask");
        ImageSimilarity s;
        {
          py::gil_scoped_release release;
          s = compareImages(image_a, image_b, mask_image);
        }
        py::dict out;
        out["ssim"] = s.ssim;
        out["ssim_in_mask"] = s.ssim_in_mask;
        out["psnr_db"] = s.psnr_db;
        out["mean_abs_diff"] = s.mean_abs_diff;
        return out;
      },
      py::arg("a"), py::arg("b"), py::arg("mask") = py::none(),
      "How alike two uint8 images are ((rows, cols) grey or (rows, cols, 3) bgr, same shape): "
      "dict ssim (Wang et al. 2004, Gaussian window sigma 1.5, per-channel mean; equals "
      "skimage.metrics.structural_similarity(a, b, channel_axis=2, gaussian_weights=True, "
      "sigma=1.5, use_sample_covariance=False, data_range=255)), ssim_in_mask (the SSIM map's "
      "mean where mask (rows, cols) uint8 is non-zero, the 5 px border left out as in ssim; "
      "None: everywhere), psnr_db (peak 255; inf for identical images), mean_abs_diff (grey "
      "levels). Raises norm2tex.Error for images of different shape or smaller than 11 x 11.");

  py::class_<RenderedFrame>(m, "RenderedFrame", "One DIGIT frame (copies, yours to keep).")
      .def_readonly("image", &RenderedFrame::image, "(rows, cols, 3) uint8, bgr8")
      .def_readonly("depth", &RenderedFrame::depth,
                    "(rows, cols) float32: the gel's deformation, metres")
      .def_readonly("contact_mask", &RenderedFrame::contact_mask,
                    "(rows, cols) uint8: 255 where the object touches the gel")
      .def_readonly("textured", &RenderedFrame::textured, "whether the texture overlay ran")
      .def_readonly("shear", &RenderedFrame::shear,
                    "(rows, cols, 2) float32: the gel surface's lateral displacement (x, y in the "
                    "gel frame), metres; None when render() was given no shear load")
      .def_readonly("markers", &RenderedFrame::markers,
                    "dict of (n, 2) float32 arrays: rest_px and current_px (x = column, y = row), "
                    "displacement_mm (gel frame); None when the sensor has no markers")
      .def_readonly("slip_fraction", &RenderedFrame::slip_fraction,
                    "fraction of the contact's area that slips (0 stick .. 1 sliding); None "
                    "without a shear load");

  py::class_<ShearLoad>(m, "ShearLoad",
                        "The contact's tangential load on the gel (gel frame): what moves its "
                        "surface sideways and carries the markers.")
      .def(py::init([](const Eigen::Vector2d& force_n, double torque_nm,
                       std::optional<double> friction) {
             ShearLoad load;
             load.force_n = force_n;
             load.torque_nm = torque_nm;
             load.friction = friction;
             return load;
           }),
           py::arg("force_n") = Eigen::Vector2d::Zero(), py::arg("torque_nm") = 0.0,
           py::arg("friction") = py::none())
      .def_readwrite("force_n", &ShearLoad::force_n,
                     "tangential force the object applies to the gel, (x, y), N")
      .def_readwrite("torque_nm", &ShearLoad::torque_nm,
                     "twisting moment about the gel's +z through the contact, N m (x towards y)")
      .def_readwrite("friction", &ShearLoad::friction,
                     "Coulomb coefficient gel-object; None: the sensor's shear.friction");

  py::class_<TactileRenderer>(
      m, "TactileRenderer",
      "One DIGIT's rendering: object pose in the gel frame -> H_sensor -> H_final = H_sensor + "
      "beta H_local -> gel smoothing -> DIGIT shading (+ noise). Not thread-safe: one per "
      "thread or sensor.")
      .def(py::init<const SensorModel&>(), py::arg("sensor") = makeDigitSensorModel())
      .def(
          "set_object",
          [](TactileRenderer& r, std::shared_ptr<TexturedMesh> mesh,
             std::shared_ptr<HeightAtlas> atlas, double beta_mm) {
            return r.setObject(mesh, atlas, atlas ? beta_mm : 0.0);
          },
          py::arg("mesh"), py::arg("atlas") = nullptr, py::arg("beta_mm") = 0.0,
          "The object to render, with H_global `atlas` at depth beta_mm (mm; 0 or no atlas: "
          "textureless). Returns a warning ('' if none), e.g. texture asked for a mesh "
          "without UVs.")
      .def(
          "render",
          [](TactileRenderer& r, const py::object& object_in_gel, std::int64_t noise_seed,
             std::optional<double> normal_force_n, std::optional<ShearLoad> shear) {
            const Eigen::Isometry3d pose = poseFromPython(object_in_gel, "object_in_gel");
            const TactileFrame* frame;
            {
              py::gil_scoped_release release;
              frame = &r.render(pose, noise_seed, normal_force_n, shear);
            }
            return copyFrame(*frame, shear.has_value());
          },
          py::arg("object_in_gel"), py::arg("noise_seed") = -1,
          py::arg("normal_force_n") = py::none(), py::arg("shear") = py::none(),
          "Renders the object at `object_in_gel` (the object frame in the gel frame, metres: a "
          "4x4 matrix or (xyz, quaternion xyzw)); noise drawn from noise_seed (< 0: none). "
          "normal_force_n (N): the contact's force, which sets how much of the texture the gel "
          "follows when the sensor's conformity is on (None: the gel law's force for the press). "
          "shear (a ShearLoad): the contact's tangential force and twist, which move the gel's "
          "surface and its markers (frame.shear, frame.markers, frame.slip_fraction). "
          "Returns a RenderedFrame. Raises norm2tex.Error for a non-finite pose, force or load, "
          "or no object.")
      .def_property_readonly("background",
                             [](const TactileRenderer& r) { return toNumpy(r.shader().background()); },
                             "the no-contact frame without noise, (rows, cols, 3) uint8")
      .def_property_readonly("sensor", &TactileRenderer::model);
}

}  // namespace python
}  // namespace norm2tex
