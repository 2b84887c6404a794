#pragma once
/**
 * How exact the shared direct light is (docs/metrics.md, "Direct-light accuracy"): a rasterised
 * emission + direct image against the path tracer's emission + direct layers, both linear RGB
 * with the same pixel footprint. Luminance is Rec.709; non-finite pixels of either image are
 * left out of every sum (and counted).
 */
#include <cstddef>

#include "core/image/image.h"

namespace gilab::metrics {

struct DirectAccuracy {
    /** Mean luminance of the test over the reference's (1 = the right amount of light). */
    double energyRatio = 0.0;
    /** Light the test puts into pixels the reference has at exactly 0 (in shadow, outside a
     *  spot's cone, or the background), over the reference's total: leaks. */
    double shadowLeak = 0.0;
    /** Light missing from pixels the reference lights (sum of max(ref - test, 0)) over the
     *  reference's total: false shadows and acne. */
    double missing = 0.0;
    size_t shadowPixels = 0;  // pixels the reference has at 0
    size_t pixels = 0;        // finite pixels compared
    size_t nonFinite = 0;     // pixels left out
};

/** Throws gilab::Error on different sizes or fewer than 3 channels. */
DirectAccuracy directAccuracy(const Image& test, const Image& reference);

}  // namespace gilab::metrics
