// Temporal instability: the technique's frame-to-frame change against the reference's, on
// Rec.709 luminance, with the reference's own noise floor (docs/metrics.md).
#include <algorithm>
#include <cmath>
#include <string>

#include "core/image/color.h"
#include "core/util/error.h"
#include "experiments/metrics/metrics.h"
#include "experiments/metrics/metrics_internal.h"

namespace gilab::metrics {

namespace {

constexpr const char* kWhat = "temporal instability";
constexpr double kWeights[3] = {double(kLuminanceR), double(kLuminanceG), double(kLuminanceB)};
/** E|N(0, s)| = s · sqrt(2/π). */
constexpr double kMeanAbsNormal = 0.79788456080286535588;

std::string sizeText(const Image& im) {
    return std::to_string(im.width()) + "x" + std::to_string(im.height());
}

/** Throws unless the frame exists, has 3 or 4 channels and the size of `first`. */
void checkFrame(const Image* frame, const char* role, size_t k, const Image* first) {
    const std::string name = std::string(kWhat) + ": " + role + " frame " + std::to_string(k);
    if (frame == nullptr) throw Error(name + " is null");
    if (frame->empty()) throw Error(name + " is empty");
    if (frame->channels() != 3 && frame->channels() != 4) {
        throw Error(name + " has " + std::to_string(frame->channels()) +
                    " channels, expected RGB or RGBA");
    }
    if (first != nullptr &&
        (frame->width() != first->width() || frame->height() != first->height())) {
        throw Error(name + " is " + sizeText(*frame) + ", reference frame 0 is " +
                    sizeText(*first));
    }
}

double lum(const Image& im, size_t p) {
    const float* px = im.data() + p * size_t(im.channels());
    return kWeights[0] * double(px[0]) + kWeights[1] * double(px[1]) + kWeights[2] * double(px[2]);
}

/** Variance of the luminance of a pixel whose channels have independent standard errors. */
double lumVariance(const Image& stdError, size_t p) {
    const float* px = stdError.data() + p * size_t(stdError.channels());
    double v = 0.0;
    for (int c = 0; c < 3; ++c)
        v += kWeights[c] * kWeights[c] * double(px[c]) * double(px[c]);
    return v;
}

using detail::number;

std::string joinNotes(const std::vector<std::string>& notes) {
    std::string out;
    for (const std::string& n : notes) {
        if (!out.empty()) out += "; ";
        out += n;
    }
    return out;
}

}  // namespace

TemporalResult computeTemporalInstability(const std::vector<const Image*>& test,
                                          const std::vector<const Image*>& reference,
                                          const std::vector<const Image*>* referenceStdError,
                                          const Mask* mask) {
    if (test.size() != reference.size()) {
        throw Error(std::string(kWhat) + ": " + std::to_string(test.size()) + " test frames but " +
                    std::to_string(reference.size()) + " reference frames");
    }
    if (referenceStdError != nullptr && referenceStdError->size() != reference.size()) {
        throw Error(std::string(kWhat) + ": " + std::to_string(referenceStdError->size()) +
                    " reference standard-error frames for " + std::to_string(reference.size()) +
                    " reference frames");
    }
    const size_t frames = reference.size();
    const Image* first = frames > 0 ? reference[0] : nullptr;
    for (size_t k = 0; k < frames; ++k) {
        checkFrame(reference[k], "reference", k, first);
        checkFrame(test[k], "test", k, first);
        if (referenceStdError != nullptr) {
            checkFrame((*referenceStdError)[k], "reference standard-error", k, first);
        }
    }

    TemporalResult result;
    result.frames = int(frames);
    if (frames < 2) {
        result.note = "fewer than 2 frames: no consecutive pair to compare";
        return result;
    }
    const int width = first->width(), height = first->height();
    detail::checkMask(mask, width, height, kWhat);
    const bool masked = mask != nullptr && !mask->empty();
    const size_t pixelCount = first->pixelCount();
    auto inRegion = [&](size_t p) { return !masked || mask->values()[p] != 0; };

    result.pairs = int(frames - 1);
    result.regionPixels = masked ? mask->count() : pixelCount;
    std::vector<std::string> notes;

    // The reference's level: mean luminance over all frames and its finite region pixels.
    double levelSum = 0.0;
    size_t levelCount = 0;
    for (size_t k = 0; k < frames; ++k) {
        for (size_t p = 0; p < pixelCount; ++p) {
            if (!inRegion(p) || !detail::isFinitePixel(*reference[k], p)) continue;
            levelSum += lum(*reference[k], p);
            ++levelCount;
        }
    }
    result.level = levelCount > 0 ? levelSum / double(levelCount) : kNaN;

    // d for every pixel and pair: pooled over the region, averaged per pixel into the map.
    std::vector<double> mapSum(pixelCount, 0.0);
    std::vector<int> mapCount(pixelCount, 0);
    std::vector<float> pooled;
    pooled.reserve(result.regionPixels * size_t(result.pairs));
    double sumD = 0.0, sumFloor = 0.0;
    for (size_t k = 0; k + 1 < frames; ++k) {
        const Image& t0 = *test[k];
        const Image& t1 = *test[k + 1];
        const Image& r0 = *reference[k];
        const Image& r1 = *reference[k + 1];
        const Image* e0 = referenceStdError ? (*referenceStdError)[k] : nullptr;
        const Image* e1 = referenceStdError ? (*referenceStdError)[k + 1] : nullptr;
        for (size_t p = 0; p < pixelCount; ++p) {
            const bool finite =
                detail::isFinitePixel(t0, p) && detail::isFinitePixel(t1, p) &&
                detail::isFinitePixel(r0, p) && detail::isFinitePixel(r1, p) &&
                (e0 == nullptr || (detail::isFinitePixel(*e0, p) && detail::isFinitePixel(*e1, p)));
            const bool region = inRegion(p);
            if (!finite) {
                if (region) ++result.skippedPixels;
                continue;
            }
            const double d = std::abs((lum(t1, p) - lum(t0, p)) - (lum(r1, p) - lum(r0, p)));
            mapSum[p] += d;
            ++mapCount[p];
            if (!region) continue;
            sumD += d;
            pooled.push_back(float(d));
            if (e0 != nullptr) {
                // Independent frames: the reference change carries noise of variance
                // σ_k² + σ_{k+1}², whose expected magnitude is s·sqrt(2/π).
                sumFloor += std::sqrt(lumVariance(*e0, p) + lumVariance(*e1, p)) * kMeanAbsNormal;
            }
        }
    }
    result.samples = pooled.size();

    result.map = Image(width, height, 1);
    for (size_t p = 0; p < pixelCount; ++p) {
        result.map.data()[p] = mapCount[p] > 0 ? float(mapSum[p] / double(mapCount[p])) : kNaN;
    }

    if (result.skippedPixels > 0) {
        notes.push_back(std::to_string(result.skippedPixels) +
                        " (pixel, pair) samples left out: non-finite in a frame of the pair");
    }
    if (result.samples == 0) {
        notes.push_back("no finite (pixel, pair) sample in the region: every value is n/a");
        result.note = joinNotes(notes);
        return result;
    }
    const double n = double(result.samples);
    result.meanAbs = sumD / n;
    // 95th percentile, nearest rank: the smallest value with at least 95 % of the samples <= it.
    const size_t rank = std::max<size_t>(1, (95 * result.samples + 99) / 100);
    std::nth_element(pooled.begin(), pooled.begin() + std::ptrdiff_t(rank - 1), pooled.end());
    const double p95Abs = double(pooled[rank - 1]);
    const double floorAbs = referenceStdError != nullptr ? sumFloor / n : kNaN;
    if (referenceStdError == nullptr) {
        notes.push_back("no reference standard-error images: noise_floor and debiased are n/a");
    }

    if (std::isfinite(result.level) && result.level > 0.0) {
        result.instability = result.meanAbs / result.level;
        result.p95 = p95Abs / result.level;
        result.noiseFloor = floorAbs / result.level;
        result.debiased = std::isfinite(result.noiseFloor)
                              ? std::max(0.0, result.instability - result.noiseFloor)
                              : kNaN;
    } else {
        notes.push_back(
            std::isnan(result.level)
                ? "the reference has no finite region pixel: relative values are n/a"
                : "the reference's level (mean luminance) is not positive: relative values are "
                  "n/a");
    }
    result.note = joinNotes(notes);
    return result;
}

nlohmann::ordered_json toJson(const TemporalResult& r) {
    nlohmann::ordered_json j;
    j["frames"] = r.frames;
    j["pairs"] = r.pairs;
    j["region_pixels"] = r.regionPixels;
    j["samples"] = r.samples;
    j["skipped_pixels"] = r.skippedPixels;
    j["level"] = number(r.level);
    j["mean_abs"] = number(r.meanAbs);
    j["temporal_instability"] = number(r.instability);
    j["p95"] = number(r.p95);
    j["noise_floor"] = number(r.noiseFloor);
    j["debiased"] = number(r.debiased);
    j["note"] = r.note;
    return j;
}

void writeTemporalMapPng(const std::string& path, const TemporalResult& result, double fullScale) {
    if (result.map.empty()) {
        throw Error(std::string(kWhat) + ": no map to write (fewer than 2 frames): " + path);
    }
    if (!(fullScale > 0.0) || !std::isfinite(fullScale)) {
        throw Error(std::string(kWhat) + ": the map's full scale must be positive");
    }
    double scale = kNaN;
    if (std::isfinite(result.level) && result.level > 0.0) {
        scale = fullScale * result.level;
    } else {
        double largest = 0.0;
        for (float v : result.map.values()) {
            if (std::isfinite(v)) largest = std::max(largest, double(v));
        }
        scale = largest > 0.0 ? largest : 1.0;
    }
    Image normalised = result.map;
    for (float& v : normalised.values()) {
        if (std::isfinite(v)) v = float(std::clamp(double(v) / scale, 0.0, 1.0));
    }
    writeMagmaPng(path, normalised);
}

}  // namespace gilab::metrics
