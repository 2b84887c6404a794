#pragma once
/**
 * The reference cache key: an XXH3-128 hash of everything that changes a reference image
 * (docs/reference_cache.md). Two inputs are hashed, on purpose both:
 *   - the resolved Scene (after variants, overrides and --resolution): every vertex, index,
 *     triangle material, material field, texture pixel and sampler state, light field, camera
 *     field and the resolution. This catches what the files alone cannot: scene-file overrides,
 *     variants, procedural scenes and any change in how a loader interprets the same bytes.
 *   - the bytes of every file in Scene::loadedFiles. This catches what the data alone might
 *     miss: a file change that reaches the image through a field the data hash forgot.
 * plus the ReferenceSettings that change the image (maxBounces, rouletteStartBounce, estimator,
 * seed; not batchSamples, see path_tracer.h) and ref::kRendererVersion. Floats are hashed by
 * their bit patterns. Names, paths, warnings and the preview exposure are not hashed: they do
 * not change the EXR.
 */
#include <string>

#include <nlohmann/json.hpp>

#include "core/scene/scene.h"
#include "reference/reference_settings.h"

namespace gilab::ref {

/** Bumped when the key's byte layout changes (independent of kRendererVersion). */
inline constexpr int kKeyFormatVersion = 1;

struct ReferenceKey {
    std::string hex;                     // 32 lower-case hex digits
    nlohmann::ordered_json description;  // what went into it, for the sidecar
};

/** The key and its description. Throws gilab::Error naming a loaded file it cannot read. */
ReferenceKey computeReferenceKey(const Scene& scene, const ReferenceSettings& settings);
/** Only the key: computeReferenceKey(scene, settings).hex. */
std::string referenceKey(const Scene& scene, const ReferenceSettings& settings);

/** XXH3-128 of the flattened scene data alone (no files, settings or version), hex. */
std::string hashSceneData(const Scene& scene);
/** XXH3-128 of a file's bytes, hex. Throws gilab::Error naming the file if it cannot be read. */
std::string hashFileContents(const std::string& path, uint64_t* sizeBytes = nullptr);

}  // namespace gilab::ref
