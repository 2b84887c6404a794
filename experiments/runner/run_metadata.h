#pragma once
/** JSON blocks shared by every output sidecar: provenance, device, scene, timings, memory. */
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/image/image.h"
#include "core/scene/scene.h"
#include "core/technique/frame_harness.h"

namespace gilab {
namespace vk {
class Context;
}

namespace cli {

/** git commit, version, compiler, build type, date (UTC, ISO 8601), host, CPU, command line. */
nlohmann::ordered_json provenanceJson(const std::string& commandLine);
/** A diagnostic pass, "<technique>/diag.<name>": it measures the method, is timed, and is left
 *  out of the frame's GPU time (docs/timing.md). */
bool isDiagnosticPass(const std::string& name);
/** The frames' GPU time (top-level passes, diagnostics left out): IQR / median, NaN for fewer
 *  than 4 frames or a zero median. */
double frameGpuIqrOverMedian(const std::vector<FrameTiming>& frames);
nlohmann::ordered_json deviceJson(const vk::Context& ctx);
nlohmann::ordered_json sceneToJson(const Scene& scene);
/** {median, q1, q3, iqr, min, max, samples} of a list of times (ms). */
nlohmann::ordered_json summaryJson(const std::vector<double>& values);
/** Setup times, the warm-up, then per-frame CPU and per-pass GPU times as median / IQR over the
 *  frames. */
nlohmann::ordered_json timingJson(const SetupTiming& setup, const std::vector<FrameTiming>& frames,
                                  const WarmupResult& warmup);
/**
 * The dynamic frames (FrameTiming::dynamic) of an animated run: frame CPU time (update
 * included), frame GPU time (frame passes + update passes), update CPU time, and each update
 * pass's GPU time, as median / IQR (docs/timing.md "Dynamic frames").
 */
nlohmann::ordered_json dynamicTimingJson(const std::vector<FrameTiming>& frames);
nlohmann::ordered_json memoryJson(const MemoryReport& memory);
/**
 * The Vulkan validation messages captured since the last call (or since the context was made):
 * {enabled, errors, warnings, messages}. Clears them, so each run reports only its own.
 */
nlohmann::ordered_json takeValidationJson(vk::Context& ctx);
/** errors + warnings of a takeValidationJson() block (0 for anything else). */
uint32_t validationMessageCount(const nlohmann::ordered_json& validation);
/** The layers that hold radiance or albedo, where a negative value is a defect. */
bool isRadianceLayer(const std::string& name);
/**
 * {layer: {nan_pixels, inf_pixels, negative_pixels}}; `nonFinite` gets the NaN and Inf pixels
 * of every layer plus the negative pixels of the radiance layers (isRadianceLayer).
 */
nlohmann::ordered_json finiteJson(const std::vector<ImageLayer>& layers, size_t* nonFinite);
std::string isoDateUtc();

Scene loadSceneOrDefault(const std::string& path);

}  // namespace cli
}  // namespace gilab
