#pragma once
// The energy check every GI technique passes on a simple scene: the sum of its indirect layer
// against the path tracer's one-bounce indirect layer (tests that claim one bounce).
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/image/image.h"
#include "core/scene/scene.h"
#include "reference/path_tracer.h"

namespace gilab::test {

/** Sum of the "indirect" layer's RGB values; a failure (and -1) when the layer is missing or any
 *  value is NaN, infinite or negative. */
inline double indirectLayerSum(const std::vector<ImageLayer>& layers) {
    for (const ImageLayer& l : layers) {
        if (l.name != "indirect") continue;
        double sum = 0.0;
        for (int y = 0; y < l.image.height(); ++y)
            for (int x = 0; x < l.image.width(); ++x)
                for (int c = 0; c < 3; ++c) {
                    const float v = l.image.at(x, y, c);
                    if (!std::isfinite(v) || v < 0.0f) {
                        ADD_FAILURE() << "indirect pixel " << x << "," << y << " = " << v;
                        return -1.0;
                    }
                    sum += v;
                }
        return sum;
    }
    ADD_FAILURE() << "no indirect layer";
    return -1.0;
}

/** Sum of the path tracer's one-bounce indirect layer (max 1 bounce, `spp` samples). */
inline double oneBounceReferenceSum(const Scene& scene, uint32_t spp, uint64_t seed = 7) {
    ref::ReferenceSettings settings;
    settings.maxBounces = 1;
    settings.seed = seed;
    ref::PathTracer tracer(scene, settings);
    ref::Accumulator acc;
    acc.reset(scene.settings.width, scene.settings.height);
    EXPECT_TRUE(tracer.addSamples(acc, spp));
    const Image bounce = ref::meanImage(acc, ref::Layer::Bounce1);  // named: values() of a
    double sum = 0.0;                                               // temporary would dangle
    for (float v : bounce.values())
        sum += v;
    return sum;
}

}  // namespace gilab::test
