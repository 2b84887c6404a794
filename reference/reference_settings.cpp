#include "reference/reference_settings.h"

#include <nlohmann/json.hpp>

namespace gilab::ref {

const char* layerName(Layer layer) {
    switch (layer) {
        case Layer::Full:
            return "full";
        case Layer::Emission:
            return "emission";
        case Layer::Direct:
            return "direct";
        case Layer::Bounce1:
            return "bounce1";
        case Layer::Bounce2:
            return "bounce2";
        case Layer::Bounce3Plus:
            return "bounce3plus";
    }
    return "?";
}

const char* pixelFilterName(PixelFilter f) {
    return f == PixelFilter::Center ? "center" : "box";
}

const char* estimatorName(Estimator e) {
    switch (e) {
        case Estimator::Mis:
            return "mis";
        case Estimator::NeeOnly:
            return "nee";
        case Estimator::BsdfOnly:
            return "bsdf";
    }
    return "?";
}

nlohmann::ordered_json settingsJson(const ReferenceSettings& settings) {
    // Tripwire: this binding names every field, so a field added to ReferenceSettings stops the
    // build here until it is serialised below (and, if it does not change the image, listed in
    // kSettingsNotInKey, reference/scene_hash.h). Keep the order of the struct.
    const auto& [maxBounces, rouletteStartBounce, rouletteThreshold, estimator, seed, pixelFilter,
                 sampler, sobolReplicate, batchSamples] = settings;
    static_assert(sizeof(ReferenceSettings) == 40, "ReferenceSettings changed: serialise it here");
    return {{"max_bounces", maxBounces},
            {"roulette_start_bounce", rouletteStartBounce},
            {"roulette_threshold", rouletteThreshold},
            {"estimator", estimatorName(estimator)},
            {"seed", seed},
            {"pixel_filter", pixelFilterName(pixelFilter)},
            {"sampler", samplerKindName(sampler)},
            {"sobol_replicate", sobolReplicate},
            {"batch_samples", batchSamples}};
}

}  // namespace gilab::ref
