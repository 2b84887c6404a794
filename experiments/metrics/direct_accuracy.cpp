#include "experiments/metrics/direct_accuracy.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/image/color.h"
#include "core/util/error.h"

namespace gilab::metrics {

DirectAccuracy directAccuracy(const Image& test, const Image& reference) {
    if (test.width() != reference.width() || test.height() != reference.height())
        throw Error("direct accuracy: the images differ in size");
    if (test.channels() < 3 || reference.channels() < 3)
        throw Error("direct accuracy: RGB images needed");
    DirectAccuracy a;
    double sumTest = 0.0, sumRef = 0.0, leak = 0.0, missing = 0.0;
    for (int y = 0; y < test.height(); ++y)
        for (int x = 0; x < test.width(); ++x) {
            const double t = luminance(test.at(x, y, 0), test.at(x, y, 1), test.at(x, y, 2));
            const double r =
                luminance(reference.at(x, y, 0), reference.at(x, y, 1), reference.at(x, y, 2));
            if (!std::isfinite(t) || !std::isfinite(r)) {
                ++a.nonFinite;
                continue;
            }
            ++a.pixels;
            sumTest += t;
            sumRef += r;
            if (r <= 0.0) {
                ++a.shadowPixels;
                leak += t;
            } else {
                missing += std::max(r - t, 0.0);
            }
        }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    a.energyRatio = sumRef > 0.0 ? sumTest / sumRef : nan;
    a.shadowLeak = sumRef > 0.0 ? leak / sumRef : nan;
    a.missing = sumRef > 0.0 ? missing / sumRef : nan;
    return a;
}

}  // namespace gilab::metrics
