#include "core/voxel/distance_transform.h"

#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/util/error.h"

namespace gilab {
namespace {

constexpr int64_t kInfinite = -1;                  // no feature seen yet along this line
constexpr uint64_t kExactFloatLimit = 1ull << 24;  // integers up to here are exact in float

/** Per-thread scratch for one 1D line: input, output and the lower envelope. */
struct LineScratch {
    std::vector<int64_t> f;     // input squared distance, kInfinite when none
    std::vector<int64_t> d;     // output squared distance
    std::vector<int64_t> v;     // vertices (positions) of the envelope's parabolas
    std::vector<int64_t> zNum;  // left boundary of parabola k is zNum[k] / zDen[k]
    std::vector<int64_t> zDen;  // always > 0

    explicit LineScratch(size_t n) : f(n), d(n), v(n), zNum(n), zDen(n) {}
};

/** Transform s.f[0..n) into s.d[0..n) (FH 2012 §2.1, Algorithm DT(f)); false if all infinite. */
bool transformLine(LineScratch& s, int64_t n) {
    // Build the lower envelope of the parabolas rooted at the finite samples.
    int64_t k = -1;
    for (int64_t q = 0; q < n; ++q) {
        if (s.f[q] == kInfinite) continue;
        int64_t num = 0, den = 1;
        while (k >= 0) {
            // FH 2012 Eq. 4: intersection ((f(q) + q^2) - (f(p) + p^2)) / (2q - 2p)
            const int64_t p = s.v[k];
            num = (s.f[q] + q * q) - (s.f[p] + p * p);
            den = 2 * (q - p);
            // Drop p when q already wins at p's left boundary (exact rational compare).
            if (k > 0 && num * s.zDen[k] <= s.zNum[k] * den) {
                --k;
                continue;
            }
            break;
        }
        ++k;
        s.v[k] = q;
        s.zNum[k] = num;  // unused for k == 0 (boundary at -infinity)
        s.zDen[k] = den;
    }
    if (k < 0) return false;

    // Evaluate the envelope, stepping right while the next boundary lies before q.
    const int64_t last = k;
    k = 0;
    for (int64_t q = 0; q < n; ++q) {
        while (k < last && s.zNum[k + 1] < q * s.zDen[k + 1])
            ++k;
        const int64_t p = s.v[k];
        s.d[q] = (q - p) * (q - p) + s.f[p];
    }
    return true;
}

/** One pass along an axis: lineCount lines of n samples, line i starting at base(i). */
template <class BaseFn>
void transformAxis(std::vector<float>& grid, size_t lineCount, int64_t n, size_t stride,
                   BaseFn base) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, lineCount), [&](const auto& range) {
        LineScratch s{static_cast<size_t>(n)};
        for (size_t line = range.begin(); line != range.end(); ++line) {
            float* g = grid.data() + base(line);
            for (int64_t q = 0; q < n; ++q) {
                const float x = g[q * stride];
                s.f[q] = std::isinf(x) ? kInfinite : int64_t(x);
            }
            if (!transformLine(s, n)) continue;  // all infinite: leave the line as it is
            for (int64_t q = 0; q < n; ++q)
                g[q * stride] = float(s.d[q]);
        }
    });
}

std::string describe(const GridDims& dims) {
    return std::to_string(dims.nx) + "x" + std::to_string(dims.ny) + "x" + std::to_string(dims.nz);
}

void validate(const std::vector<uint8_t>& feature, const GridDims& dims) {
    const std::string where = "squaredDistanceTransform: grid " + describe(dims);
    if (dims.nx == 0 || dims.ny == 0 || dims.nz == 0) {
        throw Error(where + " has a zero dimension");
    }
    const uint64_t dx = dims.nx - 1, dy = dims.ny - 1, dz = dims.nz - 1;
    if (dx * dx + dy * dy + dz * dz >= kExactFloatLimit) {
        throw Error(where + " is too large: its squared diagonal reaches 2^24, past exact float");
    }
    if (feature.size() != dims.count()) {
        throw Error(where + " needs " + std::to_string(dims.count()) + " feature values, got " +
                    std::to_string(feature.size()));
    }
}

}  // namespace

std::vector<float> squaredDistanceTransform(const std::vector<uint8_t>& feature,
                                            const GridDims& dims) {
    validate(feature, dims);
    std::vector<float> grid(feature.size());
    for (size_t i = 0; i < grid.size(); ++i)
        grid[i] = feature[i] ? 0.0f : kNoFeatureDistance;

    const size_t nx = dims.nx, ny = dims.ny, nz = dims.nz;
    // Pass along x: line (y, z) starts at nx * (y + ny * z).
    transformAxis(grid, ny * nz, nx, 1, [&](size_t line) { return nx * line; });
    // Pass along y: line (x, z) starts at x + nx * ny * z.
    transformAxis(grid, nx * nz, ny, nx,
                  [&](size_t line) { return line % nx + nx * ny * (line / nx); });
    // Pass along z: line (x, y) starts at x + nx * y.
    transformAxis(grid, nx * ny, nz, nx * ny, [&](size_t line) { return line; });
    return grid;
}

std::vector<float> distanceTransform(const std::vector<uint8_t>& feature, const GridDims& dims) {
    std::vector<float> grid = squaredDistanceTransform(feature, dims);
    for (float& value : grid)
        value = std::sqrt(value);
    return grid;
}

}  // namespace gilab
