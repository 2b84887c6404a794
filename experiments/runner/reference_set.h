#pragma once
/**
 * The reference of one scene, split so that each technique is compared with the light it claims
 * to compute (docs/experiments.md, "Bounce matching"):
 *   n = 0 bounces        emission + direct
 *   n indirect bounces   emission + direct + bounce1 + ... + bounce_n   (bounce3plus for n >= 3
 *                        only when the reference's max_bounces <= n, else the full image)
 *   all bounces          full
 * The matched standard error is sqrt(sum of the layers' variances) (layers' covariance ignored:
 * they come from the same paths, so this is an approximation; for "all" the full layer's own
 * standard error is used, which is exact).
 */
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/image/image.h"
#include "experiments/metrics/metrics.h"
#include "reference/cache.h"

namespace gilab::exp {

struct MatchedReference {
    std::string name;  // e.g. "emission+direct+bounce1"
    Image final;       // what the technique's `final` layer is compared with
    Image finalStdError;
    Image indirect;  // what its `indirect` layer is compared with (empty for 0 bounces)
    Image indirectStdError;
    Image fullIndirect;  // all indirect light of the reference (regions, "vs full" metrics)
    Image full;
    Image fullStdError;
    const class ReferenceSet* set = nullptr;  // the set it came from (shared noise floors)
};

class ReferenceSet {
public:
    explicit ReferenceSet(ref::ReferenceResult result);
    const ref::ReferenceResult& result() const { return m_result; }
    /** `bounces` as TechniqueInfo::indirectBounces (kAllBounces = all). */
    MatchedReference match(int bounces) const;
    /**
     * metrics::computeNoiseFloor(image, options), computed on first use and reused by every
     * run compared with this reference: the reference-only half of the error bars, the same
     * numbers at a fraction of the cost (docs/metrics.md, "Cost"). `basis` names the image (one
     * of this set's matched images) and whatever of `options` differs between callers; the
     * rest (tone map, ppd, resamples, seed) is one experiment's and must not change.
     */
    const metrics::NoiseFloorSamples& noiseFloor(const std::string& basis, const Image& image,
                                                 const metrics::MetricOptions& options) const;
    /** The reference's max_bounces (its sidecar's settings; kAllBounces when not recorded). */
    int maxBounces() const;
    /**
     * The bounce floor b (docs/experiments.md, "Bounce matching"): the exact b-bounce image
     * match(b).final scored against the full reference, metrics::computeMetrics(match(b).final,
     * full, options), computed on first use and reused by every run compared with this
     * reference. nullopt when match(b) is the full image itself (maxBounces() <= b). `options`
     * (tone map, ppd, referenceStdError = the full standard error, the "full" noise floor) are
     * one experiment's, as for noiseFloor(); the key is b and options.resampleFlip.
     */
    const std::optional<metrics::MetricSet>& bounceFloor(
        int bounces, const metrics::MetricOptions& options) const;

private:
    const Image& mean(ref::Layer layer) const;
    const Image& stdError(ref::Layer layer) const;
    ref::ReferenceResult m_result;
    std::vector<ImageLayer> m_mean;
    std::vector<ImageLayer> m_stdError;
    mutable std::map<std::string, metrics::NoiseFloorSamples> m_noiseFloors;
    mutable std::map<std::pair<int, bool>, std::optional<metrics::MetricSet>> m_bounceFloors;
};

}  // namespace gilab::exp
