#include "core/voxel/distance_transform.h"

#include <algorithm>
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

// ---------------------------------------------------------------------------------------------
// Chessboard distance and opening
// ---------------------------------------------------------------------------------------------

constexpr int64_t kNoFeature = kNoFeatureChessboard;

/** Per-thread scratch for one 1D chessboard line. */
struct ChessboardScratch {
    std::vector<int64_t> f;  // input, kNoFeature when none
    std::vector<int64_t> d;  // output
    std::vector<int64_t> v;  // distance: positions of the envelope's cones; opening: deque
    std::vector<int64_t> t;  // distance: first position where cone v[k] is on the envelope

    explicit ChessboardScratch(size_t n) : f(n), d(n), v(n), t(n) {}
};

/** The cone of sample j (value fj) at position u: max(|u - j|, fj). */
int64_t cone(int64_t j, int64_t fj, int64_t u) {
    return std::max(u > j ? u - j : j - u, fj);
}

/** For samples j < k with values a, b: the smallest integer u with cone(k, b, u) <= cone(j, a, u).
 *  The set of such u is [sep, infinity) (unit slopes). |u - k| <= max(|u - j|, a) holds from
 *  min(ceil((j + k) / 2), k - a) on; b <= max(|u - j|, a) always when a >= b, else for
 *  u >= j + b (u <= j - b lies left of the first condition). */
int64_t separation(int64_t j, int64_t a, int64_t k, int64_t b) {
    const int64_t first = std::min((j + k + 1) / 2, k - a);
    return a >= b ? first : std::max(first, j + b);
}

/** 1D chessboard pass, s.f[0..n) into s.d[0..n): d(u) = min_j max(|u - j|, f(j)) as the lower
 *  envelope of the cones (stack scan as in FH 2012 §2.1 and Meijster, Roerdink & Hesselink
 *  2000); false if every sample is kNoFeature. */
bool chessboardLine(ChessboardScratch& s, int64_t n) {
    int64_t k = -1;
    for (int64_t q = 0; q < n; ++q) {
        if (s.f[q] == kNoFeature) continue;
        // Drop cones that q matches or beats from their first envelope position on.
        while (k >= 0 && cone(q, s.f[q], s.t[k]) <= cone(s.v[k], s.f[s.v[k]], s.t[k]))
            --k;
        if (k < 0) {
            k = 0;
            s.v[0] = q;
            s.t[0] = 0;
            continue;
        }
        const int64_t from = separation(s.v[k], s.f[s.v[k]], q, s.f[q]);  // > s.t[k]
        if (from < n) {
            ++k;
            s.v[k] = q;
            s.t[k] = from;
        }
    }
    if (k < 0) return false;
    const int64_t last = k;
    k = 0;
    for (int64_t u = 0; u < n; ++u) {
        while (k < last && s.t[k + 1] <= u)
            ++k;
        s.d[u] = cone(s.v[k], s.f[s.v[k]], u);
    }
    return true;
}

/** 1D opening pass, s.f[0..n) into s.d[0..n): d(u) = max f(c) over c with |u - c| <= f(c) - 1
 *  (0 if none). Two sweeps with a monotone deque (centres c <= u, then c >= u): a centre is
 *  dropped once a later one is at least as large (whose interval then reaches at least as far),
 *  so the deque's values decrease from its head, which is the answer once expired heads are
 *  gone. Always true (all samples finite). */
bool openingLine(ChessboardScratch& s, int64_t n) {
    int64_t* deque = s.v.data();
    int64_t head = 0, tail = 0;
    for (int64_t u = 0; u < n; ++u) {  // centres c <= u reaching u: c + f(c) - 1 >= u
        if (s.f[u] > 0) {
            while (tail > head && s.f[deque[tail - 1]] <= s.f[u])
                --tail;
            deque[tail++] = u;
        }
        while (tail > head && deque[head] + s.f[deque[head]] - 1 < u)
            ++head;
        s.d[u] = tail > head ? s.f[deque[head]] : 0;
    }
    head = tail = 0;
    for (int64_t u = n - 1; u >= 0; --u) {  // centres c >= u reaching u: c - f(c) + 1 <= u
        if (s.f[u] > 0) {
            while (tail > head && s.f[deque[tail - 1]] <= s.f[u])
                --tail;
            deque[tail++] = u;
        }
        while (tail > head && deque[head] - s.f[deque[head]] + 1 > u)
            ++head;
        if (tail > head) s.d[u] = std::max(s.d[u], s.f[deque[head]]);
    }
    return true;
}

/** One pass of a chessboard line function along an axis, as transformAxis. Lines whose starts
 *  are adjacent in memory (consecutive x for the y and z passes) are gathered in blocks of up to
 *  kBlock, so each strided step reads a run of contiguous values rather than one. */
template <class LineFn, class BaseFn>
void chessboardAxis(std::vector<uint32_t>& grid, size_t lineCount, int64_t n, size_t stride,
                    BaseFn base, LineFn lineFn) {
    constexpr size_t kBlock = 16;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, lineCount, kBlock), [&](const auto& range) {
        ChessboardScratch s{static_cast<size_t>(n)};
        std::vector<uint32_t> block(kBlock * n);  // block[q * width + b]: line b, sample q
        for (size_t first = range.begin(); first != range.end();) {
            uint32_t* g = grid.data() + base(first);
            size_t width = 1;
            while (stride != 1 && width < kBlock && first + width != range.end() &&
                   base(first + width) == base(first) + width) {
                ++width;
            }
            for (int64_t q = 0; q < n; ++q) {
                for (size_t b = 0; b < width; ++b)
                    block[q * width + b] = g[q * stride + b];
            }
            bool changed = false;
            for (size_t b = 0; b < width; ++b) {
                for (int64_t q = 0; q < n; ++q)
                    s.f[q] = block[q * width + b];
                if (!lineFn(s, n)) continue;  // nothing to do: leave the line as it is
                changed = true;
                for (int64_t q = 0; q < n; ++q)
                    block[q * width + b] = uint32_t(s.d[q]);
            }
            if (changed) {
                for (int64_t q = 0; q < n; ++q) {
                    for (size_t b = 0; b < width; ++b)
                        g[q * stride + b] = block[q * width + b];
                }
            }
            first += width;
        }
    });
}

/** The three passes x, y, z of a chessboard line function over the grid, in place. */
template <class LineFn>
void chessboardPasses(std::vector<uint32_t>& grid, const GridDims& dims, LineFn lineFn) {
    const size_t nx = dims.nx, ny = dims.ny, nz = dims.nz;
    chessboardAxis(
        grid, ny * nz, nx, 1, [&](size_t line) { return nx * line; }, lineFn);
    chessboardAxis(
        grid, nx * nz, ny, nx, [&](size_t line) { return line % nx + nx * ny * (line / nx); },
        lineFn);
    chessboardAxis(
        grid, nx * ny, nz, nx * ny, [&](size_t line) { return line; }, lineFn);
}

void validateChessboard(size_t size, const GridDims& dims, const char* who, const char* what) {
    const std::string where = std::string(who) + ": grid " + describe(dims);
    if (dims.nx == 0 || dims.ny == 0 || dims.nz == 0) {
        throw Error(where + " has a zero dimension");
    }
    if (size != dims.count()) {
        throw Error(where + " needs " + std::to_string(dims.count()) + " " + what + ", got " +
                    std::to_string(size));
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

std::vector<uint32_t> chessboardDistanceTransform(const std::vector<uint8_t>& feature,
                                                  const GridDims& dims) {
    validateChessboard(feature.size(), dims, "chessboardDistanceTransform", "feature values");
    std::vector<uint32_t> grid(feature.size());
    for (size_t i = 0; i < grid.size(); ++i)
        grid[i] = feature[i] ? 0u : kNoFeatureChessboard;
    chessboardPasses(grid, dims, chessboardLine);
    return grid;
}

std::vector<uint32_t> chessboardOpening(const std::vector<uint32_t>& distance,
                                        const GridDims& dims) {
    validateChessboard(distance.size(), dims, "chessboardOpening", "distance values");
    const size_t none = size_t(std::count(distance.begin(), distance.end(), kNoFeatureChessboard));
    if (none == distance.size()) return distance;  // no feature anywhere: nothing to open
    if (none != 0) {
        throw Error("chessboardOpening: grid " + describe(dims) + " mixes " + std::to_string(none) +
                    " kNoFeatureChessboard values with finite ones (not a distance map)");
    }
    std::vector<uint32_t> grid = distance;
    chessboardPasses(grid, dims, openingLine);
    // Already so for a distance map (a feature voxel lies in no empty cube); kept for any map.
    for (size_t i = 0; i < grid.size(); ++i) {
        if (distance[i] == 0) grid[i] = 0;
    }
    return grid;
}

}  // namespace gilab
