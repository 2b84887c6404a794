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

/**
 * The final image against the references with 0, 1 and 2 indirect bounces, whatever the
 * technique claims: {"0": M, "1": M, "2": M}. Puts every technique, the direct baseline
 * included, on the same footing as a one- or two-bounce technique (report, done criteria).
 */
nlohmann::ordered_json computeBounceLadder(const std::vector<ImageLayer>& layers,
                                           const ReferenceSet& references,
                                           const MetricOptionsSpec& spec, const ToneMap& tonemap);

/**
 * The bounce floors of `references` (docs/experiments.md, "Bounce matching"): the path
 * tracer's exact 0-, 1- and 2-bounce images (match(b).final) against the full reference, with
 * the same options and resampled FLIP error bars as a run's "final_vs_full":
 * {"0": M, "1": M, "2": M}; an entry whose b-bounce image is the full image itself (the
 * reference's max_bounces <= b) is {"same_as_full": true} instead. Computed once per reference
 * (ReferenceSet::bounceFloor) and written into every run's result. A technique claiming b
 * bounces that scores better than floor b against the full reference makes up for the bounces
 * it lacks with surplus energy.
 */
nlohmann::ordered_json computeBounceFloors(const ReferenceSet& references,
                                           const MetricOptionsSpec& spec, const ToneMap& tonemap);

/**
 * The light every technique shares: its emission + direct layers against the reference's
 * emission + direct (`directReference` = ReferenceSet::match(0)). metrics::toJson(MetricSet).
 */
nlohmann::ordered_json computeDirectMetrics(const std::vector<ImageLayer>& layers,
                                            const MatchedReference& directReference,
                                            const MetricOptionsSpec& spec, const ToneMap& tonemap);

}  // namespace gilab::exp
