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
 * plus the ReferenceSettings, as the dump of keySettingsJson() (settingsJson(), the sidecar's own
 * serialisation, less the fields named below), and ref::kRendererVersion. The scene's floats
 * are hashed by their bit patterns, the settings' by their exact JSON text. Names, paths,
 * warnings and the preview exposure are not hashed: they do not change the EXR.
 */
#include <array>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "core/scene/scene.h"
#include "reference/reference_settings.h"

namespace gilab::ref {

/** Bumped when the key's byte layout changes (independent of kRendererVersion).
 *  2: the settings are hashed as the dump of keySettingsJson() (issue 45). */
inline constexpr int kKeyFormatVersion = 2;

/**
 * The fields of settingsJson() (by their JSON names) that are left out of the key, because they
 * never change the image. Every other field is in the key: a field is excluded here or not at
 * all, never by being forgotten (docs/reference_cache.md, "The key").
 *   batch_samples  how many samples a pass adds; by the determinism contract (path_tracer.h)
 *                  samples [N, 2N) added to an N-sample accumulator give exactly the 2N-sample
 *                  image whatever the batching, so renders that differ only in it share an entry.
 * The stop criteria (samples, relative error, time budget) are not settings: they decide how
 * far an entry is grown, never which entry it is.
 */
inline constexpr std::array<std::string_view, 1> kSettingsNotInKey = {"batch_samples"};
/** Fields that only the Sobol sampler reads: left out of the key while the sampler is
 *  "independent" (the image does not depend on them then), in it with "sobol". */
inline constexpr std::array<std::string_view, 1> kSobolOnlySettings = {"sobol_replicate"};

/** settingsJson(settings) less kSettingsNotInKey, and less kSobolOnlySettings unless the
 *  sampler is Sobol: the settings part of the key (its dump() is hashed) and of its description. */
nlohmann::ordered_json keySettingsJson(const ReferenceSettings& settings);

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
