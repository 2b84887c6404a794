#pragma once
/** Robust summaries of repeated measurements (docs/timing.md): median and interquartile range. */
#include <cstddef>
#include <vector>

namespace gilab {

struct Summary {
    size_t count = 0;
    double median = 0.0;
    double q1 = 0.0;  // 25th percentile
    double q3 = 0.0;  // 75th percentile
    double min = 0.0;
    double max = 0.0;
    double mean = 0.0;
    double iqr() const { return q3 - q1; }
};

/** Percentiles by linear interpolation between order statistics (type 7, as numpy's default). */
double percentile(std::vector<double> values, double p);
Summary summarize(const std::vector<double>& values);

}  // namespace gilab
