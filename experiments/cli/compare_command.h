#pragma once
/** `gilab compare`: every metric between a test image and a reference (docs/compare.md). */
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/metrics/metrics.h"

namespace gilab::cli {

/** Options of `gilab compare`, also used by tests. */
struct CompareOptions {
    std::string test;                  // "image.exr[:layer]"; the first image
    std::string reference;             // "image.exr[:layer]"; the second image is the reference
    std::vector<std::string> metrics;  // empty = all: flip, hdr-flip, relmse, psnr, ssim
    std::string mask;                  // optional mask image (channel 0 > 0.5 = inside)
    std::string outDir;                // "" = print only; else error maps (PNG, EXR) + JSON
    std::string flipExposure;          // "start:stop" HDR-FLIP exposure range, "" = automatic
    double ppd = 0.0;                  // FLIP pixels per degree, 0 = the default
    bool json = false;                 // print the JSON summary instead of the table
};
/** Prints the comparison (table or JSON); returns 0, or prints the message and returns 2
 *  (kExitUsage) on a bad command-line value (cli::UsageError, cli.h). Other failures throw
 *  gilab::Error (exit 1 in cli.cpp). */
int runCompare(const CompareOptions& options);

/** "file[:layer]": the suffix after the last ':' is a layer only if the whole text is not an
 *  existing file (and the suffix has no '/'). */
struct ImageArgument {
    std::string path;
    std::optional<std::string> layer;
};
ImageArgument parseImageArgument(const std::string& text);

/** The metric groups of --metrics ("flip" = LDR-FLIP, "hdr-flip", "relmse" = MSE, RMSE and
 *  relMSE, "psnr" = LDR and HDR, "ssim"), in canonical order; empty = all. Throws
 *  cli::UsageError. */
std::vector<std::string> parseMetricNames(const std::vector<std::string>& names);
/** "start:stop" in stops (start <= stop, finite); throws cli::UsageError. */
std::pair<double, double> parseFlipExposure(const std::string& text);

/** What compareImages computed. */
struct CompareResult {
    std::vector<std::string> selected;  // canonical metric groups
    metrics::MetricSet metrics;         // the selected metrics; the others stay NaN
    bool exposureFixed = false;         // --flip-exposure given
    bool zeroMedianFallback = false;    // HDR-FLIP's automatic range used the fallback
    std::vector<std::string> notes;
    std::vector<std::string> warnings;  // printed to stderr: e.g. the pixel footprints differ
    std::vector<std::string> files;     // written under outDir
    nlohmann::ordered_json json;        // the summary (compare.json)
};
/** Reads both images (and the mask), computes the selected metrics with gilab::metrics and,
 *  with outDir, writes the error maps and compare.json. Throws cli::UsageError (bad option
 *  values) or gilab::Error (files, layers, sizes). */
CompareResult compareImages(const CompareOptions& options);

}  // namespace gilab::cli
