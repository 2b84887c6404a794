#include "experiments/runner/same_vpl.h"

#include <algorithm>
#include <cmath>

#include "core/technique/frame_harness.h"
#include "core/util/error.h"
#include "core/util/progress.h"
#include "core/vpl/vpl.h"
#include "experiments/metrics/metrics.h"
#include "reference/embree_scene.h"
#include "reference/texture_lookup.h"
#include "reference/vpl_reference.h"

namespace gilab::exp {
namespace {

std::vector<glm::vec4> toVec4(const Image& img) {
    std::vector<glm::vec4> out(img.pixelCount(), glm::vec4(0.0f));
    const int c = img.channels();
    for (size_t i = 0; i < out.size(); ++i)
        for (int k = 0; k < std::min(c, 4); ++k)
            out[i][k] = img.values()[i * size_t(c) + size_t(k)];
    return out;
}

Image toRgb(const std::vector<glm::vec4>& v, int w, int h) {
    Image img(w, h, 3);
    for (size_t i = 0; i < v.size(); ++i)
        for (int k = 0; k < 3; ++k)
            img.values()[i * 3 + size_t(k)] = v[i][k];
    return img;
}

Image sum(const Image& a, const Image& b) {
    Image out = a;
    for (size_t i = 0; i < out.values().size(); ++i)
        out.values()[i] += b.values()[i];
    return out;
}

double mse(const Image& a, const Image& b) {
    return metrics::computeMse(a, b).value;
}

double relMse(const Image& a, const Image& b) {
    return metrics::computeRelMse(a, b).value;
}

double meanOf(const Image& a) {
    double s = 0.0;
    for (float v : a.values())
        if (std::isfinite(v)) s += v;
    return a.values().empty() ? 0.0 : s / double(a.values().size());
}

nlohmann::ordered_json errors(const Image& test, const Image& reference, const ToneMap& tm,
                              const Image& refLdr) {
    const Image ldr = tonemapToSrgb(test, tm);
    return {{"mse", mse(test, reference)}, {"mse_8bit", 255.0 * 255.0 * mse(ldr, refLdr)}};
}

}  // namespace

nlohmann::ordered_json computeSameVplReference(FrameHarness& harness, const Scene& scene,
                                               std::vector<ImageLayer>& layers,
                                               const ToneMap& tonemap) {
    VplSet set;
    Image position, normal, albedo;
    if (!harness.readVplFrame(set, position, normal, albedo)) return nullptr;
    const int w = position.width(), h = position.height();
    ref::VplReferenceInput in;
    in.width = uint32_t(w);
    in.height = uint32_t(h);
    in.position = toVec4(position);
    in.normal = toVec4(normal);
    in.albedo = toVec4(albedo);
    in.vpls = std::move(set.vpls);
    in.clampDistance = set.clampDistance;
    in.bounceScale = set.bounceScale;
    size_t valid = 0;
    for (const GpuVpl& v : in.vpls)
        valid += v.position.w >= 0.5f ? 1 : 0;

    const ref::TextureLookup textures(scene.textures);
    const ref::EmbreeScene embree(scene, textures);
    Progress progress("same-VPL reference: " + std::to_string(valid) + " VPLs x " +
                          std::to_string(w) + "x" + std::to_string(h) + " shadow rays",
                      1000);
    // One pass per bounce (flux.w: 1 or 2), so the exact light is known bounce by bounce; the
    // totals are their sums (each VPL is shaded once either way).
    ref::VplReferenceResult r;
    r.exact.assign(size_t(w) * size_t(h), glm::vec4(0.0f));
    r.unshadowed = r.exact;
    nlohmann::ordered_json byBounce;
    const std::vector<GpuVpl> all = std::move(in.vpls);
    for (int bounce : {1, 2}) {
        in.vpls.clear();
        for (const GpuVpl& v : all)
            if ((v.flux.w > 1.5f ? 2 : 1) == bounce) in.vpls.push_back(v);
        if (in.vpls.empty()) continue;
        const ref::VplReferenceResult part = ref::shadeVplsWithShadowRays(
            embree, in,
            [&](double f) { progress.update(size_t((f + double(bounce - 1)) * 500.0)); });
        for (size_t i = 0; i < r.exact.size(); ++i) {
            r.exact[i] += part.exact[i];
            r.unshadowed[i] += part.unshadowed[i];
        }
        r.rays += part.rays;
        r.seconds += part.seconds;
        r.invalidPixels = std::max(r.invalidPixels, part.invalidPixels);
        r.invalidVpls += part.invalidVpls;
        size_t count = 0;
        for (const GpuVpl& v : in.vpls)
            count += v.position.w >= 0.5f ? 1 : 0;
        byBounce[std::to_string(bounce)] = {
            {"vpls", count},
            {"exact_mean", meanOf(toRgb(part.exact, w, h))},
            {"unshadowed_mean", meanOf(toRgb(part.unshadowed, w, h))}};
    }
    progress.finish();

    const Image exact = toRgb(r.exact, w, h);
    const Image unshadowed = toRgb(r.unshadowed, w, h);
    const Image* finalImg = findLayer(layers, "final");
    const Image* indirect = findLayer(layers, "indirect");
    const Image* direct = findLayer(layers, "direct");
    const Image* emission = findLayer(layers, "emission");
    if (!finalImg || !indirect || !direct || !emission)
        throw Error("same-VPL reference: the run's layers lack final/indirect/direct/emission");
    const Image base = sum(*emission, *direct);
    const Image reference = sum(base, exact);
    const Image refLdr = tonemapToSrgb(reference, tonemap);

    nlohmann::ordered_json out;
    out["vpls"] = valid;
    out["shadow_rays"] = r.rays;
    out["seconds"] = r.seconds;
    out["invalid_pixels"] = r.invalidPixels;
    out["invalid_vpls"] = r.invalidVpls;
    out["clamp_distance"] = set.clampDistance;
    out["table_ii"] = {{"direct_only", errors(base, reference, tonemap, refLdr)},
                       {"unshadowed", errors(sum(base, unshadowed), reference, tonemap, refLdr)},
                       {"method", errors(*finalImg, reference, tonemap, refLdr)}};
    const double exactMean = meanOf(exact);
    out["indirect"] = {
        {"rel_mse", relMse(*indirect, exact)},
        {"rel_mse_unshadowed", relMse(unshadowed, exact)},
        {"energy_ratio", exactMean > 0.0 ? meanOf(*indirect) / exactMean : 0.0},
        {"energy_ratio_unshadowed", exactMean > 0.0 ? meanOf(unshadowed) / exactMean : 0.0},
        {"mean", meanOf(*indirect)},
        {"exact_mean", exactMean}};
    // Mean RGB radiance of the VPLs of each bounce, exact and unshadowed (per-bounce accounting:
    // techniques/ssvp/ssvp_tables.py sets them beside the path tracer's bounce layers).
    out["by_bounce"] = byBounce;
    layers.push_back({"vpl_exact", exact});
    layers.push_back({"vpl_unshadowed", unshadowed});
    return out;
}

}  // namespace gilab::exp
