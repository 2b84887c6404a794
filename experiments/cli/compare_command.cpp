// `gilab compare`: a test image against a reference with the metric library the runner uses
// (experiments/metrics), error maps and a JSON summary. docs/compare.md.
#include "experiments/cli/compare_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <tuple>

#include "core/image/image_io.h"
#include "core/util/atomic_file.h"
#include "core/util/strings.h"
#include "experiments/cli/cli.h"
#include "experiments/metrics/flip_constants.h"
#include "experiments/metrics/metrics_internal.h"

namespace gilab::cli {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

const std::vector<std::string> kMetricGroups = {"relmse", "psnr", "ssim", "flip", "hdr-flip"};

/** One input image: the argument as given, where it came from, and its pixels. */
struct LoadedImage {
    std::string argument;
    ImageArgument source;
    Image image;
    std::string pixelFilter;  // the file's kPixelFilterAttribute, "" = not recorded
};

bool isExrPath(const std::string& path) {
    return toLowerAscii(fs::path(path).extension().string()) == ".exr";
}

std::string quoted(const std::string& text) {
    return "'" + text + "'";
}

std::string sizeText(const Image& image) {
    return std::to_string(image.width()) + "x" + std::to_string(image.height());
}

std::string layerList(const std::vector<ImageLayer>& layers) {
    std::vector<std::string> names;
    for (const ImageLayer& l : layers)
        names.push_back(l.name.empty() ? "(plain R,G,B)" : l.name);
    return joinStrings(names, ", ");
}

Image readExrLayer(const ImageArgument& arg) {
    std::vector<ImageLayer> layers = readExrLayers(arg.path);
    const std::string wanted = arg.layer.value_or("");
    for (ImageLayer& l : layers) {
        if (l.name == wanted) return std::move(l.image);
    }
    if (wanted.empty()) {
        throw Error(arg.path + ": no plain R,G,B channels; name a layer as " + arg.path +
                    ":<layer> (layers: " + layerList(layers) + ")");
    }
    std::vector<std::string> names;
    for (const ImageLayer& l : layers)
        names.push_back(l.name);
    const std::string close = findClosestMatch(wanted, names);
    throw Error(arg.path + ": no layer " + quoted(wanted) +
                (close.empty() ? "" : " (did you mean " + quoted(close) + "?)") +
                "; layers: " + layerList(layers));
}

LoadedImage loadImage(const std::string& text, const char* role) {
    LoadedImage out{text, parseImageArgument(text), {}};
    const ImageArgument& arg = out.source;
    std::error_code ec;
    if (!fs::is_regular_file(arg.path, ec)) {
        throw Error(std::string(role) + " image " + quoted(text) + ": file not found" +
                    (arg.layer ? " (read as file " + quoted(arg.path) + ", layer " +
                                     quoted(*arg.layer) + ")"
                               : ""));
    }
    if (isExrPath(arg.path)) {
        out.image = readExrLayer(arg);
        out.pixelFilter = readImageStringAttribute(arg.path, kPixelFilterAttribute);
    } else if (arg.layer && !arg.layer->empty()) {
        throw Error(std::string(role) + " image " + quoted(text) + ": layers (':" + *arg.layer +
                    "') need an EXR file, and " + quoted(arg.path) + " is not one");
    } else {
        out.image = readImageRgb(arg.path);
    }
    return out;
}

bool isRgb(const Image& image) {
    return image.channels() == 3 || image.channels() == 4;
}

std::string describe(const LoadedImage& in) {
    return quoted(in.argument) + " (" + sizeText(in.image) + ", " +
           std::to_string(in.image.channels()) + " channel" +
           (in.image.channels() == 1 ? "" : "s") + ")";
}

void checkInputs(const LoadedImage& test, const LoadedImage& ref) {
    if (!isRgb(test.image) || !isRgb(ref.image)) {
        throw Error("channel mismatch: test " + describe(test) + ", reference " + describe(ref) +
                    "; compare needs RGB or RGBA images");
    }
    if (test.image.width() != ref.image.width() || test.image.height() != ref.image.height()) {
        throw Error("size mismatch: test " + quoted(test.argument) + " is " + sizeText(test.image) +
                    ", reference " + quoted(ref.argument) + " is " + sizeText(ref.image) +
                    " (render both at one size: `gilab render` and `gilab reference` take "
                    "--resolution WxH)");
    }
}

std::optional<metrics::Mask> loadMask(const std::string& text, const Image& ref,
                                      const std::string& refArgument) {
    if (text.empty()) return std::nullopt;
    const LoadedImage in = loadImage(text, "mask");
    if (in.image.width() != ref.width() || in.image.height() != ref.height()) {
        throw Error("size mismatch: mask " + quoted(text) + " is " + sizeText(in.image) +
                    ", images " + quoted(refArgument) + " are " + sizeText(ref));
    }
    return metrics::Mask::fromImage(in.image, 0.5f);
}

bool selected(const std::vector<std::string>& groups, const char* name) {
    return std::find(groups.begin(), groups.end(), name) != groups.end();
}

bool parseNumber(const std::string& text, double& value) {
    const std::string t = trimString(text);
    if (t.empty()) return false;
    char* end = nullptr;
    value = std::strtod(t.c_str(), &end);
    return end == t.c_str() + t.size() && std::isfinite(value);
}

// --- metrics ---------------------------------------------------------------------------------

/** The pixels every metric pools over: the region minus non-finite pixels (as computeMetrics). */
metrics::Mask includedPixels(const metrics::PixelSelection& sel, int width, int height) {
    metrics::Mask mask(width, height, false);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            mask.set(x, y, sel.include[size_t(y) * size_t(width) + size_t(x)] != 0);
        }
    }
    return mask;
}

/** LDR-FLIP of the displayed images, exactly as computeMetrics does (compute_metrics.cpp). */
metrics::FlipResult computeDisplayedLdrFlip(const Image& test, const Image& ref,
                                            const ToneMap& tonemap, double ppd,
                                            const metrics::Mask& include) {
    Image testF, refF;
    metrics::detail::makeFinitePair(test, ref, testF, refF);
    metrics::FlipResult r = metrics::computeLdrFlip(tonemapToSrgb(testF, tonemap),
                                                    tonemapToSrgb(refF, tonemap), ppd, &include);
    for (size_t p = 0; p < test.pixelCount(); ++p) {
        if (!metrics::detail::isFinitePixel(test, p) || !metrics::detail::isFinitePixel(ref, p)) {
            r.errorMap.data()[p] = std::numeric_limits<float>::quiet_NaN();
        }
    }
    return r;
}

/** Whether the reference's median luminance (finite pixels, negatives as 0) is 0, and whether
 *  no pixel is bright at all: HDR-FLIP's automatic range then falls back (docs/metrics.md). */
struct MedianCheck {
    bool zeroMedian = false;
    bool allBlack = false;
};
MedianCheck checkMedianLuminance(const Image& ref) {
    size_t finite = 0, dark = 0;
    const auto& w = metrics::flip::kRgbToXyz[1];
    for (size_t p = 0; p < ref.pixelCount(); ++p) {
        if (!metrics::detail::isFinitePixel(ref, p)) continue;
        const float* px = ref.data() + p * size_t(ref.channels());
        ++finite;
        if (!(w[0] * px[0] + w[1] * px[1] + w[2] * px[2] > 0.0)) ++dark;
    }
    // Sorted ascending, the median is 0 iff the value at index n/2 is 0.
    return {dark >= finite / 2 + 1 || finite == 0, dark == finite};
}

/** Per-pixel mean over R, G, B of (t − r)² and (t − r)² / (r² + ε); NaN where excluded. */
void computePixelErrorMaps(const Image& test, const Image& ref, Image& squared, Image& relative) {
    squared = Image(test.width(), test.height(), 1);
    relative = Image(test.width(), test.height(), 1);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (size_t p = 0; p < test.pixelCount(); ++p) {
        if (!metrics::detail::isFinitePixel(test, p) || !metrics::detail::isFinitePixel(ref, p)) {
            squared.data()[p] = relative.data()[p] = nan;
            continue;
        }
        double se = 0.0, rel = 0.0;
        for (int c = 0; c < 3; ++c) {
            const double t = test.data()[p * size_t(test.channels()) + size_t(c)];
            const double r = ref.data()[p * size_t(ref.channels()) + size_t(c)];
            se += (t - r) * (t - r);
            rel += (t - r) * (t - r) / (r * r + metrics::kRelMseEpsilon);
        }
        squared.data()[p] = float(se / 3.0);
        relative.data()[p] = float(rel / 3.0);
    }
}

/** Values clamped to [0, 1] (NaN kept) for a magma preview. */
Image clamped01(const Image& map, bool invert) {
    Image out = map;
    for (float& v : out.values()) {
        if (std::isfinite(v)) v = std::clamp(invert ? 1.0f - v : v, 0.0f, 1.0f);
    }
    return out;
}

/** Everything computed, before the output. */
struct Computed {
    metrics::MetricSet set;
    metrics::MetricMaps maps;
    Image squaredMap, relMseMap;
};

Computed computeSelected(const Image& test, const Image& ref, const metrics::Mask* region,
                         const std::vector<std::string>& groups,
                         const metrics::HdrFlipOptions& flipOptions, const ToneMap& tonemap) {
    const metrics::PixelSelection sel = metrics::selectPixels(test, ref, region);
    const metrics::Mask include = includedPixels(sel, test.width(), test.height());
    Computed c;
    metrics::MetricSet& m = c.set;
    m.pixels = sel.pixels;
    m.regionPixels = sel.regionPixels;
    m.testNonFinite = sel.testNonFinite;
    m.refNonFinite = sel.refNonFinite;
    m.hasNonFinite = sel.hasNonFinite();
    if (selected(groups, "relmse")) {
        m.mse = metrics::computeMse(test, ref, &include).value;
        m.rmse = std::sqrt(m.mse);
        m.relMse = metrics::computeRelMse(test, ref, &include).value;
        computePixelErrorMaps(test, ref, c.squaredMap, c.relMseMap);
    }
    if (selected(groups, "psnr")) {
        m.psnrLdr = metrics::computePsnrLdr(test, ref, tonemap, &include).value;
        m.psnrHdrPeak = metrics::getHdrPeak(ref);
        const bool peakOk = m.psnrHdrPeak > 0.0 && std::isfinite(m.psnrHdrPeak);
        m.psnrHdr = peakOk ? metrics::computePsnrHdr(test, ref, &include, m.psnrHdrPeak).value
                           : metrics::kNaN;
    }
    if (selected(groups, "ssim")) {
        metrics::SsimResult s = metrics::computeSsim(test, ref, tonemap, &include);
        m.ssim = s.mean.value;
        c.maps.ssim = std::move(s.map);
    }
    if (selected(groups, "flip")) {
        metrics::FlipResult f =
            computeDisplayedLdrFlip(test, ref, tonemap, flipOptions.ppd, include);
        m.flipLdr = f.stats;
        c.maps.flipLdr = std::move(f.errorMap);
    }
    if (selected(groups, "hdr-flip")) {
        m.flipExposures = {*flipOptions.startExposure, *flipOptions.stopExposure,
                           *flipOptions.exposureCount};
        metrics::FlipResult f = metrics::computeHdrFlip(test, ref, flipOptions, &include);
        m.flip = f.stats;
        c.maps.flip = std::move(f.errorMap);
    }
    return c;
}

// --- notes and JSON --------------------------------------------------------------------------

std::string formatNumber(double v) {
    if (std::isnan(v)) return "n/a";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

Json imageJson(const LoadedImage& in) {
    const FiniteStats s = countNonFinite(in.image);
    return {{"argument", in.argument},
            {"path", in.source.path},
            {"layer", in.source.layer ? Json(*in.source.layer) : Json(nullptr)},
            {"width", in.image.width()},
            {"height", in.image.height()},
            {"channels", in.image.channels()},
            {"pixel_filter", in.pixelFilter.empty() ? Json(nullptr) : Json(in.pixelFilter)},
            {"nan_pixels", s.nanPixels},
            {"inf_pixels", s.infPixels},
            {"negative_pixels", s.negativePixels}};
}

/** toJson(MetricSet) (the runner's metrics.json format) without the unselected metrics and
 *  the error bars (compare has no stderr image). */
Json metricsJson(const metrics::MetricSet& m, const std::vector<std::string>& groups) {
    Json j = metrics::toJson(m);
    const std::vector<std::pair<const char*, std::vector<const char*>>> keys = {
        {"relmse", {"mse", "rmse", "rel_mse"}},
        {"psnr", {"psnr_ldr", "psnr_hdr", "psnr_hdr_peak"}},
        {"ssim", {"ssim"}},
        {"flip", {"flip_ldr"}},
        {"hdr-flip", {"flip"}}};
    for (const auto& [group, names] : keys) {
        if (selected(groups, group)) continue;
        for (const char* k : names)
            j.erase(k);
    }
    j.erase("error_bars");
    j.erase("within_reference_noise");
    return j;
}

void addInputNotes(const char* role, const Image& image, std::vector<std::string>& notes) {
    const FiniteStats s = countNonFinite(image);
    if (!s.allFinite()) {
        notes.push_back(std::string(role) + " has " + std::to_string(s.nanPixels) + " NaN and " +
                        std::to_string(s.infPixels) +
                        " Inf pixels; they are left out of every metric (NaN in the maps)");
    }
    if (s.negativePixels > 0) {
        notes.push_back(std::string(role) + " has " + std::to_string(s.negativePixels) +
                        " pixels with a negative channel; counted, used as they are");
    }
    if (image.channels() == 4) notes.push_back(std::string(role) + "'s 4th channel is ignored");
}

void addMetricNotes(const CompareResult& r, std::vector<std::string>& notes) {
    const metrics::MetricSet& m = r.metrics;
    if (m.pixels == 0) notes.push_back("no pixel is included: every metric is n/a");
    if (std::isinf(m.psnrHdr) || std::isinf(m.psnrLdr)) {
        notes.push_back("PSNR is +inf (zero error); compare.json writes it as null");
    }
    if (selected(r.selected, "psnr") && m.pixels > 0 && std::isnan(m.psnrHdr)) {
        notes.push_back("PSNR (HDR) is n/a: the reference has no positive finite value (peak)");
    }
}

// --- files -----------------------------------------------------------------------------------

void writeMapPair(const fs::path& dir, const std::string& name, const Image& map,
                  const Image& preview, std::vector<std::string>& files) {
    writeExrLayers((dir / (name + ".exr")).string(), {{name, map}});
    metrics::writeMagmaPng((dir / (name + ".png")).string(), preview);
    files.push_back(name + ".exr");
    files.push_back(name + ".png");
}

void writeOutputs(const fs::path& dir, const Computed& c, CompareResult& r) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir)) {
        throw Error(dir.string() + ": cannot create the output folder: " + ec.message());
    }
    if (!c.maps.flip.empty()) writeMapPair(dir, "flip_hdr", c.maps.flip, c.maps.flip, r.files);
    if (!c.maps.flipLdr.empty()) {
        writeMapPair(dir, "flip_ldr", c.maps.flipLdr, c.maps.flipLdr, r.files);
    }
    if (!c.maps.ssim.empty()) {
        writeMapPair(dir, "ssim", c.maps.ssim, clamped01(c.maps.ssim, true), r.files);
    }
    if (!c.relMseMap.empty()) {
        writeExrLayers((dir / "relmse.exr").string(),
                       {{"rel_mse", c.relMseMap}, {"squared_error", c.squaredMap}});
        metrics::writeMagmaPng((dir / "relmse.png").string(), clamped01(c.relMseMap, false));
        r.files.push_back("relmse.exr");
        r.files.push_back("relmse.png");
    }
    r.files.push_back("compare.json");
    r.json["files"] = r.files;
    writeFileAtomic(dir / "compare.json", r.json.dump(2) + "\n");
}

// --- printing --------------------------------------------------------------------------------

void printRow(const char* name, double value, const std::string& detail = "") {
    if (detail.empty()) {
        std::printf("  %-20s %s\n", name, formatNumber(value).c_str());
    } else {
        std::printf("  %-20s %-12s %s\n", name, formatNumber(value).c_str(), detail.c_str());
    }
}

std::string flipDetail(const metrics::FlipStats& s) {
    return "weighted median " + formatNumber(s.weightedMedian) + ", p95 " +
           formatNumber(s.weightedP95) + ", max " + formatNumber(s.max);
}

void printInput(const char* role, const Json& j) {
    std::printf("%-10s %s  %dx%d, %d channels, NaN %zu, Inf %zu, negative %zu\n", role,
                j["argument"].get<std::string>().c_str(), j["width"].get<int>(),
                j["height"].get<int>(), j["channels"].get<int>(), j["nan_pixels"].get<size_t>(),
                j["inf_pixels"].get<size_t>(), j["negative_pixels"].get<size_t>());
}

void printTable(const CompareResult& r, const CompareOptions& options) {
    const metrics::MetricSet& m = r.metrics;
    printInput("test", r.json["test"]);
    printInput("reference", r.json["reference"]);
    const std::string where = options.mask.empty() ? "" : " in mask " + quoted(options.mask);
    std::printf("%-10s %zu of %zu pixels%s (excluded: test %zu, reference %zu non-finite)\n",
                "pixels", m.pixels, m.regionPixels, where.c_str(), m.testNonFinite, m.refNonFinite);
    std::printf("\n  %-20s %s\n", "metric", "value");
    if (selected(r.selected, "relmse")) {
        printRow("MSE", m.mse);
        printRow("RMSE", m.rmse);
        printRow("relMSE", m.relMse, "eps " + formatNumber(metrics::kRelMseEpsilon));
    }
    if (selected(r.selected, "psnr")) {
        printRow("PSNR HDR (dB)", m.psnrHdr, "peak " + formatNumber(m.psnrHdrPeak));
        printRow("PSNR LDR (dB)", m.psnrLdr, "8-bit sRGB, exposure 0 EV, clamp");
    }
    if (selected(r.selected, "ssim")) printRow("SSIM", m.ssim);
    if (selected(r.selected, "flip"))
        printRow("FLIP (LDR) mean", m.flipLdr.mean, flipDetail(m.flipLdr));
    if (selected(r.selected, "hdr-flip")) {
        printRow("HDR-FLIP mean", m.flip.mean, flipDetail(m.flip));
        const std::string range = formatNumber(m.flipExposures.start) + " .. " +
                                  formatNumber(m.flipExposures.stop) + " stops, " +
                                  std::to_string(m.flipExposures.count) + " exposures (" +
                                  (r.exposureFixed ? "fixed" : "automatic") + ")";
        std::printf("  %-20s %s\n", "HDR-FLIP exposures", range.c_str());
    }
    if (!r.notes.empty()) std::printf("\n");
    for (const std::string& note : r.notes)
        std::printf("note: %s\n", note.c_str());
    if (!r.files.empty()) {
        std::printf("\nwrote %s: %s\n", options.outDir.c_str(), joinStrings(r.files, ", ").c_str());
    }
}

}  // namespace

ImageArgument parseImageArgument(const std::string& text) {
    std::error_code ec;
    const size_t colon = text.rfind(':');
    if (colon == std::string::npos || fs::exists(text, ec)) return {text, std::nullopt};
    const std::string layer = text.substr(colon + 1);
    if (layer.find('/') != std::string::npos) return {text, std::nullopt};
    return {text.substr(0, colon), layer};
}

std::vector<std::string> parseMetricNames(const std::vector<std::string>& names) {
    std::vector<std::string> wanted;
    for (const std::string& raw : names) {
        const std::string name = toLowerAscii(trimString(raw));
        if (name.empty()) continue;
        if (name == "all") return kMetricGroups;
        if (!selected(kMetricGroups, name.c_str())) {
            const std::string close = findClosestMatch(name, kMetricGroups);
            throw UsageError("--metrics: unknown metric " + quoted(raw) +
                             (close.empty() ? "" : " (did you mean " + quoted(close) + "?)") +
                             "; known: flip, hdr-flip, relmse, psnr, ssim");
        }
        wanted.push_back(name);
    }
    if (wanted.empty()) return kMetricGroups;
    std::vector<std::string> out;
    for (const std::string& g : kMetricGroups) {
        if (selected(wanted, g.c_str())) out.push_back(g);
    }
    return out;
}

std::pair<double, double> parseFlipExposure(const std::string& text) {
    const size_t colon = text.find(':');
    double start = 0.0, stop = 0.0;
    if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos ||
        !parseNumber(text.substr(0, colon), start) || !parseNumber(text.substr(colon + 1), stop)) {
        throw UsageError(
            "--flip-exposure: expected start:stop in stops (finite numbers, e.g. "
            "-4:2), got " +
            quoted(text));
    }
    if (start > stop) {
        throw UsageError("--flip-exposure: start " + formatShortest(start) + " is above stop " +
                         formatShortest(stop));
    }
    return {start, stop};
}

CompareResult compareImages(const CompareOptions& options) {
    CompareResult r;
    r.selected = parseMetricNames(options.metrics);
    if (!options.outDir.empty()) checkOutputFolder("--out", options.outDir);
    if (options.ppd < 0.0 || !std::isfinite(options.ppd)) {
        throw UsageError("--ppd: must be positive, got " + formatShortest(options.ppd));
    }
    metrics::HdrFlipOptions flipOptions;
    flipOptions.ppd = options.ppd > 0.0 ? options.ppd : metrics::kDefaultPpd;
    r.exposureFixed = !options.flipExposure.empty();
    if (r.exposureFixed) {
        std::tie(flipOptions.startExposure, flipOptions.stopExposure) =
            parseFlipExposure(options.flipExposure);
    }

    const LoadedImage test = loadImage(options.test, "test");
    const LoadedImage ref = loadImage(options.reference, "reference");
    checkInputs(test, ref);
    const std::optional<metrics::Mask> mask = loadMask(options.mask, ref.image, ref.argument);

    // The range the library computes (or the fixed one), then passed explicitly, as
    // computeMetrics does.
    const metrics::HdrExposures ex = metrics::computeHdrExposures(ref.image, flipOptions);
    flipOptions.startExposure = ex.start;
    flipOptions.stopExposure = ex.stop;
    flipOptions.exposureCount = ex.count;

    const ToneMap tonemap{};
    const Computed c = computeSelected(test.image, ref.image, mask ? &*mask : nullptr, r.selected,
                                       flipOptions, tonemap);
    r.metrics = c.set;

    addInputNotes("test", test.image, r.notes);
    addInputNotes("reference", ref.image, r.notes);
    if (!test.pixelFilter.empty() && !ref.pixelFilter.empty() &&
        test.pixelFilter != ref.pixelFilter) {
        r.warnings.push_back(
            "the images sample different pixel footprints (test: " + test.pixelFilter +
            ", reference: " + ref.pixelFilter +
            "): edges and textures differ by that alone; render the reference with "
            "--pixel-filter " +
            test.pixelFilter + " (docs/conventions.md, \"Camera and images\")");
    }
    if (mask && mask->count() == 0) r.notes.push_back("the mask selects no pixel");
    const bool hdrFlip = selected(r.selected, "hdr-flip");
    if (hdrFlip && !r.exposureFixed) {
        const MedianCheck median = checkMedianLuminance(ref.image);
        r.zeroMedianFallback = median.zeroMedian;
        if (median.allBlack) {
            r.notes.push_back(
                "the reference is black: HDR-FLIP's exposures are c_start = c_stop = 0 "
                "(docs/metrics.md)");
        } else if (median.zeroMedian) {
            r.notes.push_back(
                "the reference's median luminance is 0 (mostly black): HDR-FLIP's stop exposure " +
                formatNumber(ex.stop) +
                " comes from the median of the positive luminances instead (fallback, "
                "docs/metrics.md)");
        }
    }
    if (r.exposureFixed && !hdrFlip) r.notes.push_back("--flip-exposure is unused: no hdr-flip");
    addMetricNotes(r, r.notes);

    r.json["test"] = imageJson(test);
    r.json["reference"] = imageJson(ref);
    r.json["mask"] =
        mask ? Json{{"argument", options.mask}, {"pixels", mask->count()}} : Json(nullptr);
    r.json["settings"] = {{"metrics", r.selected},
                          {"ppd", flipOptions.ppd},
                          {"tonemap", {{"exposure_ev", tonemap.exposureEv}, {"curve", "clamp"}}}};
    if (hdrFlip) {
        r.json["hdr_flip_exposure"] = {{"range", r.exposureFixed ? "fixed" : "automatic"},
                                       {"start", ex.start},
                                       {"stop", ex.stop},
                                       {"count", ex.count},
                                       {"zero_median_fallback", r.zeroMedianFallback}};
    }
    r.json["metrics"] = metricsJson(r.metrics, r.selected);
    r.json["notes"] = r.notes;
    r.json["warnings"] = r.warnings;
    if (!options.outDir.empty()) writeOutputs(options.outDir, c, r);
    return r;
}

int runCompare(const CompareOptions& options) {
    CompareResult r;
    try {
        r = compareImages(options);
    } catch (const UsageError& e) {
        std::fprintf(stderr, "gilab: error: %s\n", e.what());
        return kExitUsage;
    }
    for (const std::string& w : r.warnings)
        std::fprintf(stderr, "gilab: warning: %s\n", w.c_str());
    if (options.json) {
        std::printf("%s\n", r.json.dump(2).c_str());
    } else {
        printTable(r, options);
    }
    std::fflush(stdout);
    return kExitOk;
}

}  // namespace gilab::cli
