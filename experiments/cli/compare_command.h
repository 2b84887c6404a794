#pragma once
/** `gilab compare`: every metric between a test image and a reference (docs/compare.md). */
#include <string>
#include <vector>

namespace gilab::cli {

/** Options of `gilab compare`, also used by tests. */
struct CompareOptions {
    std::string test;       // "image.exr[:layer]"; the first image
    std::string reference;  // "image.exr[:layer]"; the second image is the reference
    std::vector<std::string> metrics;  // empty = all: flip, hdr-flip, relmse, psnr, ssim
    std::string mask;                  // optional mask image (channel 0 > 0.5 = inside)
    std::string outDir;                // "" = print only; else error maps (PNG, EXR) + JSON
    std::string flipExposure;          // "start:stop" HDR-FLIP exposure range, "" = automatic
    double ppd = 0.0;                  // FLIP pixels per degree, 0 = the default
    bool json = false;                 // print the JSON summary instead of the table
};
int runCompare(const CompareOptions& options);

}  // namespace gilab::cli
