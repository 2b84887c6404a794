#include "experiments/runner/run_metrics.h"

#include <cmath>

#include "core/technique/technique.h"
#include "core/util/error.h"
#include "experiments/metrics/direct_accuracy.h"
#include "experiments/metrics/metrics.h"

namespace gilab::exp {
namespace {

/** A number, or null when it is not finite. */
nlohmann::ordered_json jsonNumber(double v) {
    return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

const Image& layerImage(const std::vector<ImageLayer>& layers, const std::string& name) {
    for (const ImageLayer& l : layers)
        if (l.name == name) return l.image;
    throw Error("run output has no layer \"" + name + "\"");
}

metrics::Mask regionMask(const RegionSpec& r, const MatchedReference& ref) {
    const int w = ref.full.width(), h = ref.full.height();
    if (r.rect) {
        const auto& v = *r.rect;
        return metrics::Mask::fromNormalizedRects(w, h, {{v[0], v[1], v[2], v[3]}});
    }
    return metrics::Mask::fromIndirectFraction(ref.fullIndirect, ref.full,
                                               100.0 * r.indirectFractionAbove);
}

}  // namespace

nlohmann::ordered_json computeRunMetrics(const std::vector<ImageLayer>& layers,
                                         const MatchedReference& reference, int bounces,
                                         const MetricOptionsSpec& spec, const ToneMap& tonemap,
                                         const std::filesystem::path& outDir) {
    const Image& final = layerImage(layers, "final");
    const Image& indirect = layerImage(layers, "indirect");

    metrics::MetricOptions options;
    options.tonemap = tonemap;
    options.ppd = spec.ppd;

    // Each basis' noise floor once per reference, shared by every run (the same numbers).
    const auto shareFloor = [&](const std::string& basis, const Image& image) {
        options.noiseFloor =
            reference.set ? &reference.set->noiseFloor(basis, image, options) : nullptr;
    };
    nlohmann::ordered_json out;
    metrics::MetricMaps maps;
    options.referenceStdError = &reference.finalStdError;
    shareFloor("final:" + reference.name, reference.final);
    out["final"] = metrics::toJson(metrics::computeMetrics(final, reference.final, options, &maps));
    metrics::writeMagmaPng((outDir / "flip.png").string(), maps.flip);

    // Against all the light, whatever the technique claims: how far from full GI it is. The
    // study's basis, so its HDR-FLIP gets its error bar too (ties in docs/report.md).
    options.referenceStdError = &reference.fullStdError;
    shareFloor("full", reference.full);
    metrics::MetricMaps fullMaps;  // the report's headline basis: its map first
    out["final_vs_full"] =
        metrics::toJson(metrics::computeMetrics(final, reference.full, options, &fullMaps));
    metrics::writeMagmaPng((outDir / "flip_full.png").string(), fullMaps.flip);
    options.resampleFlip = false;  // the layers below: PSNR, SSIM and relMSE bars only

    if (bounces != 0 && !reference.indirect.empty()) {
        options.referenceStdError = &reference.indirectStdError;
        shareFloor("indirect:" + reference.name, reference.indirect);
        out["indirect"] =
            metrics::toJson(metrics::computeMetrics(indirect, reference.indirect, options));
    }
    const Image& refIndirect =
        reference.indirect.empty() ? reference.fullIndirect : reference.indirect;
    const double energy = metrics::computeEnergyRatio(indirect, refIndirect);
    out["energy_ratio"] = jsonNumber(energy);

    if (!spec.regions.empty()) {
        nlohmann::ordered_json regions;
        for (const RegionSpec& r : spec.regions) {
            metrics::MetricOptions ro = options;
            ro.noiseFloor = nullptr;  // a region's floor pools its own pixels
            ro.mask = regionMask(r, reference);
            ro.referenceStdError = &reference.finalStdError;
            nlohmann::ordered_json entry;
            entry["pixels"] = ro.mask->count();
            // The indirect energy of this region alone (e.g. a surface lit only indirectly)
            const double regionEnergy =
                metrics::computeEnergyRatio(indirect, refIndirect, &*ro.mask);
            entry["energy_ratio"] = jsonNumber(regionEnergy);
            entry["final"] = metrics::toJson(metrics::computeMetrics(final, reference.final, ro));
            if (bounces != 0 && !reference.indirect.empty()) {
                ro.referenceStdError = &reference.indirectStdError;
                entry["indirect"] =
                    metrics::toJson(metrics::computeMetrics(indirect, reference.indirect, ro));
            }
            regions[r.name] = entry;
        }
        out["regions"] = regions;
    }
    return out;
}

nlohmann::ordered_json computeBounceLadder(const std::vector<ImageLayer>& layers,
                                           const ReferenceSet& references,
                                           const MetricOptionsSpec& spec, const ToneMap& tonemap) {
    const Image& final = layerImage(layers, "final");
    metrics::MetricOptions options;
    options.tonemap = tonemap;
    options.ppd = spec.ppd;
    options.resampleFlip = false;
    nlohmann::ordered_json out;
    for (int bounces : {0, 1, 2}) {
        const MatchedReference matched = references.match(bounces);
        options.referenceStdError = &matched.finalStdError;
        nlohmann::ordered_json entry =
            metrics::toJson(metrics::computeMetrics(final, matched.final, options));
        // Mean RGB radiance of this reference: differences of consecutive entries are the
        // path tracer's bounce layers (R1 = mean(1) - mean(0), R2 = mean(2) - mean(1)).
        double sum = 0.0;
        size_t n = 0;
        for (float v : matched.final.values()) {
            if (!std::isfinite(v)) continue;
            sum += v;
            ++n;
        }
        entry["reference_mean"] = n > 0 ? sum / double(n) : 0.0;
        out[std::to_string(bounces)] = entry;
    }
    return out;
}

nlohmann::ordered_json computeBounceFloors(const ReferenceSet& references,
                                           const MetricOptionsSpec& spec, const ToneMap& tonemap) {
    // The options of "final_vs_full" in computeRunMetrics: the full standard error, resampled
    // FLIP bars and the shared "full" noise floor (the same reference, so the same floor).
    const MatchedReference full = references.match(kAllBounces);
    metrics::MetricOptions options;
    options.tonemap = tonemap;
    options.ppd = spec.ppd;
    options.referenceStdError = &full.fullStdError;
    options.noiseFloor = &references.noiseFloor("full", full.full, options);
    nlohmann::ordered_json out;
    for (int bounces : {0, 1, 2}) {
        const std::optional<metrics::MetricSet>& floor = references.bounceFloor(bounces, options);
        out[std::to_string(bounces)] =
            floor ? metrics::toJson(*floor) : nlohmann::ordered_json{{"same_as_full", true}};
    }
    return out;
}

nlohmann::ordered_json computeDirectMetrics(const std::vector<ImageLayer>& layers,
                                            const MatchedReference& directReference,
                                            const MetricOptionsSpec& spec, const ToneMap& tonemap) {
    // The light every technique shares: its emission + direct against the reference's.
    const Image& direct = layerImage(layers, "direct");
    const Image& emission = layerImage(layers, "emission");
    Image sum = direct;
    for (size_t i = 0; i < sum.values().size(); ++i)
        sum.values()[i] += emission.values()[i];
    metrics::MetricOptions options;
    options.tonemap = tonemap;
    options.ppd = spec.ppd;
    options.resampleFlip = false;
    options.referenceStdError = &directReference.finalStdError;
    nlohmann::ordered_json out =
        metrics::toJson(metrics::computeMetrics(sum, directReference.final, options));
    // Energy and leaks of the shared direct light (docs/metrics.md, "Direct-light accuracy")
    const metrics::DirectAccuracy a = metrics::directAccuracy(sum, directReference.final);
    out["energy_ratio"] = jsonNumber(a.energyRatio);
    out["shadow_leak"] = jsonNumber(a.shadowLeak);
    out["missing"] = jsonNumber(a.missing);
    return out;
}

}  // namespace gilab::exp
