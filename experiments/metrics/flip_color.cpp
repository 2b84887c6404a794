// LDR-FLIP colour pipeline [FLIP20, "Color pipeline"]: linear RGB -> YCxCz, CSF filtering,
// back to linear RGB (clamped), CIELAB, Hunt adjustment, HyAB distance, compression and the
// mapping to [0, 1]. Constants: flip_constants.h.
#include <algorithm>
#include <cmath>

#include "experiments/metrics/flip_constants.h"
#include "experiments/metrics/metrics_internal.h"

namespace gilab::metrics::detail {

namespace {

using namespace gilab::metrics::flip;

struct Matrix3 {
    double m[3][3];
};

/** Inverse of a 3×3 matrix by the adjugate. */
Matrix3 invert(const double a[3][3]) {
    Matrix3 inv{};
    const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                       a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            // Cofactor of a[j][i], divided by the determinant.
            const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
            inv.m[i][j] = (a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]) / det;
        }
    }
    return inv;
}

const Matrix3& xyzToRgbMatrix() {
    static const Matrix3 inv = invert(kRgbToXyz);
    return inv;
}

/** Reference white: XYZ of RGB (1, 1, 1). */
void getWhite(double white[3]) {
    for (int i = 0; i < 3; ++i)
        white[i] = kRgbToXyz[i][0] + kRgbToXyz[i][1] + kRgbToXyz[i][2];
}

void multiply(const double m[3][3], const double in[3], double out[3]) {
    for (int i = 0; i < 3; ++i)
        out[i] = m[i][0] * in[0] + m[i][1] * in[1] + m[i][2] * in[2];
}

/** CIELAB's f(t): cube root above δ³, linear toe below (CIE 15:2004). */
double labF(double t) {
    const double d3 = kLabDelta * kLabDelta * kLabDelta;
    return t > d3 ? std::cbrt(t) : t / (3.0 * kLabDelta * kLabDelta) + 4.0 / 29.0;
}

/** 1D Gaussian samples exp(−π² (t/ppd)² / b) for t in [−r, r] pixels. */
std::vector<float> csfGaussian(double b, double ppd, int radius) {
    std::vector<float> g(size_t(2 * radius + 1));
    for (int t = -radius; t <= radius; ++t) {
        const double deg = double(t) / ppd;
        g[size_t(t + radius)] = float(std::exp(-kPi * kPi * deg * deg / b));
    }
    return g;
}

/** Filters one YCxCz channel with its CSF: S = Σ a_i sqrt(π/b_i) g_i(x) g_i(y), sum 1. */
Plane filterWithCsf(const Plane& channel, const Csf& csf, double ppd, int radius) {
    const double amp[2] = {csf.a1 * std::sqrt(kPi / csf.b1), csf.a2 * std::sqrt(kPi / csf.b2)};
    const double bs[2] = {csf.b1, csf.b2};
    std::vector<float> gauss[2];
    double total = 0.0;
    for (int i = 0; i < 2; ++i) {
        if (amp[i] == 0.0) continue;
        gauss[i] = csfGaussian(bs[i], ppd, radius);
        double s = 0.0;
        for (float v : gauss[i])
            s += v;
        total += amp[i] * s * s;  // the 2D kernel's sum is the square of the 1D sum
    }
    Plane out(channel.width, channel.height);
    for (int i = 0; i < 2; ++i) {
        if (amp[i] == 0.0) continue;
        // Fold the term's normalised amplitude into the row kernel.
        std::vector<float> kx = gauss[i];
        const float scale = float(amp[i] / total);
        for (float& v : kx)
            v *= scale;
        const Plane term = convolveSeparable(channel, kx, gauss[i]);
        for (size_t p = 0; p < out.v.size(); ++p)
            out.v[p] += term.v[p];
    }
    return out;
}

double hyab(const double a[3], const double b[3]) {
    const double da = a[1] - b[1], db = a[2] - b[2];
    return std::abs(a[0] - b[0]) + std::sqrt(da * da + db * db);
}

}  // namespace

void linearRgbToHuntLab(double r, double g, double b, double lab[3]) {
    double white[3];
    getWhite(white);
    const double rgb[3] = {r, g, b};
    double xyz[3];
    multiply(kRgbToXyz, rgb, xyz);
    const double fx = labF(xyz[0] / white[0]), fy = labF(xyz[1] / white[1]),
                 fz = labF(xyz[2] / white[2]);
    const double l = kYccLightnessScale * fy - kYccLightnessOffset;
    lab[0] = l;
    // Hunt adjustment: chroma scales with lightness.
    lab[1] = kHuntScale * l * kYccCxScale * (fx - fy);
    lab[2] = kHuntScale * l * kYccCzScale * (fy - fz);
}

double getMaxColorError() {
    static const double cmax = [] {
        double green[3], blue[3];
        linearRgbToHuntLab(0.0, 1.0, 0.0, green);
        linearRgbToHuntLab(0.0, 0.0, 1.0, blue);
        return std::pow(hyab(green, blue), kColorExponent);
    }();
    return cmax;
}

HuntLab computeFilteredHuntLab(const RgbPlanes& linear, double ppd) {
    const int w = linear.r.width, h = linear.r.height;
    const size_t n = size_t(w) * size_t(h);
    double white[3];
    getWhite(white);
    // Linear RGB -> YCxCz.
    Plane ycc[3] = {Plane(w, h), Plane(w, h), Plane(w, h)};
    for (size_t p = 0; p < n; ++p) {
        const double rgb[3] = {linear.r.v[p], linear.g.v[p], linear.b.v[p]};
        double xyz[3];
        multiply(kRgbToXyz, rgb, xyz);
        const double xn = xyz[0] / white[0], yn = xyz[1] / white[1], zn = xyz[2] / white[2];
        ycc[0].v[p] = float(kYccLightnessScale * yn - kYccLightnessOffset);
        ycc[1].v[p] = float(kYccCxScale * (xn - yn));
        ycc[2].v[p] = float(kYccCzScale * (yn - zn));
    }
    // CSF filtering, one filter radius for all channels.
    const double sigmaDeg = std::sqrt(kCsfBMax / (2.0 * kPi * kPi));
    const int radius = int(std::ceil(kCsfRadiusSigmas * sigmaDeg * ppd));
    const Plane filtered[3] = {filterWithCsf(ycc[0], kCsfAchromatic, ppd, radius),
                               filterWithCsf(ycc[1], kCsfRedGreen, ppd, radius),
                               filterWithCsf(ycc[2], kCsfBlueYellow, ppd, radius)};
    // YCxCz -> XYZ -> linear RGB clamped to [0, 1] -> Hunt-adjusted CIELAB.
    const Matrix3& toRgb = xyzToRgbMatrix();
    HuntLab out{Plane(w, h), Plane(w, h), Plane(w, h)};
    for (size_t p = 0; p < n; ++p) {
        const double yn = (double(filtered[0].v[p]) + kYccLightnessOffset) / kYccLightnessScale;
        const double xn = double(filtered[1].v[p]) / kYccCxScale + yn;
        const double zn = yn - double(filtered[2].v[p]) / kYccCzScale;
        const double xyz[3] = {xn * white[0], yn * white[1], zn * white[2]};
        double rgb[3];
        multiply(toRgb.m, xyz, rgb);
        double lab[3];
        linearRgbToHuntLab(std::clamp(rgb[0], 0.0, 1.0), std::clamp(rgb[1], 0.0, 1.0),
                           std::clamp(rgb[2], 0.0, 1.0), lab);
        out.l.v[p] = float(lab[0]);
        out.a.v[p] = float(lab[1]);
        out.b.v[p] = float(lab[2]);
    }
    return out;
}

std::vector<float> computeColorError(const HuntLab& test, const HuntLab& ref) {
    const double cmax = getMaxColorError();
    const double cut = kColorCutoffFraction * cmax;
    std::vector<float> err(test.l.v.size());
    for (size_t p = 0; p < err.size(); ++p) {
        const double t[3] = {test.l.v[p], test.a.v[p], test.b.v[p]};
        const double r[3] = {ref.l.v[p], ref.a.v[p], ref.b.v[p]};
        const double e = std::pow(hyab(t, r), kColorExponent);
        // Small errors are stretched to [0, p_t], large ones compressed into [p_t, 1].
        const double mapped =
            e < cut ? (kColorCutoffValue / cut) * e
                    : kColorCutoffValue + (e - cut) / (cmax - cut) * (1.0 - kColorCutoffValue);
        err[p] = float(std::min(mapped, 1.0));
    }
    return err;
}

}  // namespace gilab::metrics::detail
