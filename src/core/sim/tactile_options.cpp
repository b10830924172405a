#include "sim/tactile_options.hpp"

namespace norm2tex {
namespace detail {
namespace {

TextureSource textureSource(const std::string& material_config, std::uint64_t seed, int variant) {
  TextureSource source;
  source.material_config = material_config;
  source.variant = variant;
  source.seed = seed;
  return source;
}

std::string textureKey(const std::string& material_config, std::uint64_t seed, int variant) {
  return material_config + "#" + std::to_string(seed) + "/" + std::to_string(variant);
}

}  // namespace

std::shared_ptr<const ObjectTexture> objectTextureVariant(ObjectTextureCache& cache,
                                                          const std::string& material_config,
                                                          std::uint64_t seed, int variant,
                                                          std::shared_ptr<TexturedMesh>& mesh) {
  const TextureSource source = textureSource(material_config, seed, variant);
  const std::string key = textureKey(material_config, seed, variant);
  if (!mesh->hasUvs()) {
    // Unwrapped here on this simulation's own mesh, so that every simulation sharing the cache
    // renders the same (unwrapped) mesh, even when another made the texture.
    auto unwrapped = std::make_shared<ObjectTexture>(loadObjectTexture(source, *mesh));
    return cache.get(key, [&] { return *unwrapped; }).texture;
  }
  std::shared_ptr<const TexturedMesh> with_uvs = mesh;
  return cache
      .get(key,
           [source, with_uvs] {
             TexturedMesh copy = *with_uvs;  // has UVs: left as it is
             return loadObjectTexture(source, copy);
           })
      .texture;
}

void prefetchObjectTextureVariant(ObjectTextureCache& cache, const std::string& material_config,
                                  std::uint64_t seed, int variant,
                                  const std::shared_ptr<const TexturedMesh>& mesh) {
  const TextureSource source = textureSource(material_config, seed, variant);
  cache.prefetch(textureKey(material_config, seed, variant), [source, mesh] {
    TexturedMesh copy = *mesh;
    return loadObjectTexture(source, copy);
  });
}

}  // namespace detail
}  // namespace norm2tex
