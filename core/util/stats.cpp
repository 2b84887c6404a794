#include "core/util/stats.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace gilab {

double percentile(std::vector<double> values, double p) {
    if (values.empty()) return std::nan("");
    std::sort(values.begin(), values.end());
    const double pos = std::clamp(p, 0.0, 1.0) * double(values.size() - 1);
    const size_t lo = size_t(std::floor(pos));
    const size_t hi = std::min(lo + 1, values.size() - 1);
    const double t = pos - double(lo);
    return values[lo] * (1.0 - t) + values[hi] * t;
}

Summary summarize(const std::vector<double>& values) {
    Summary s;
    s.count = values.size();
    if (values.empty()) return s;
    s.median = percentile(values, 0.5);
    s.q1 = percentile(values, 0.25);
    s.q3 = percentile(values, 0.75);
    s.min = *std::min_element(values.begin(), values.end());
    s.max = *std::max_element(values.begin(), values.end());
    s.mean = std::accumulate(values.begin(), values.end(), 0.0) / double(values.size());
    return s;
}

}  // namespace gilab
