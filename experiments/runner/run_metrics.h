#pragma once
/** Metrics of one run against its bounce-matched reference (docs/experiments.md). */
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/image/image.h"
#include "core/image/image_io.h"
#include "experiments/runner/experiment_config.h"
#include "experiments/runner/reference_set.h"

namespace gilab::exp {

/**
 * {"final": M, "final_vs_full": M, "indirect": M (bounces > 0), "regions": {name: {...}},
 *  "energy_ratio": x} where M = metrics::toJson(MetricSet). Writes the HDR-FLIP map of the
 * final image as <outDir>/flip.png (magma).
 */
nlohmann::ordered_json computeRunMetrics(const std::vector<ImageLayer>& layers,
                                         const MatchedReference& reference, int bounces,
                                         const MetricOptionsSpec& spec, const ToneMap& tonemap,
                                         const std::filesystem::path& outDir);

}  // namespace gilab::exp
