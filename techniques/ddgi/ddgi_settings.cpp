#include "ddgi_settings.h"

#include <string>

#include "core/util/error.h"

namespace gilab {
namespace {

constexpr ParamStage kRebuild = ParamStage::Rebuild;

}  // namespace

std::vector<ParamSpec> ddgiParamSpecs() {
    return {
        // Set-up: the probe volume, the atlases, the ray buffer.
        intParam("probe_grid", 8, 2, 32, "probes",
                 "probes along the volume's longest axis; the other axes get the same spacing "
                 "(at least 2 probes each). G3D default volume 8x4x8",
                 kRebuild),
        allowValue(0, intParam("probes_x", 0, 2, 64, "probes",
                               "explicit probe count along x (0 = from probe_grid)", kRebuild)),
        allowValue(0, intParam("probes_y", 0, 2, 64, "probes",
                               "explicit probe count along y (0 = from probe_grid)", kRebuild)),
        allowValue(0, intParam("probes_z", 0, 2, 64, "probes",
                               "explicit probe count along z (0 = from probe_grid)", kRebuild)),
        floatParam("volume_scale", 0.9, 0.5, 2.0, "",
                   "probe volume = the scene bounds scaled about their centre (G3D: inscribed 0.9, "
                   "circumscribed 1.05; techniques/ddgi/README.md)",
                   kRebuild),
        addCrossRule("at least 40 with relocation or classification",
                     intParam("rays_per_probe", 256, 8, 1024, "rays",
                              "rays per probe per frame (G3D 2020 and SDK 256; blog 192; "
                              "paper-era code 64)",
                              kRebuild)),
        intParam("irradiance_texels", 6, 2, 16, "texels",
                 "interior octahedral irradiance texels per side, plus a 1-texel border (SDK 6; "
                 "paper 1 and G3D 8)",
                 kRebuild),
        intParam("distance_texels", 14, 4, 32, "texels",
                 "interior octahedral distance texels per side, plus a 1-texel border (SDK 14; "
                 "paper 1 and G3D 16)",
                 kRebuild),
        boolParam("relocation", true,
                  "probe relocation (paper 2, SDK ProbeRelocationCS) on 32 fixed rays", kRebuild),
        boolParam("classification", false,
                  "probe classification (paper 2, SDK ProbeClassificationCS): inactive probes "
                  "trace only the fixed rays and are skipped by the query",
                  kRebuild),
        // Per frame: update and query.
        floatParam("hysteresis", 0.97, 0.0, 0.999, "",
                   "temporal blend weight of the old texel (SDK and blog 0.97; G3D 0.98)"),
        floatParam("irradiance_gamma", 5.0, 1.0, 10.0, "",
                   "irradiance stored as E^(1/gamma) and blended in that space (G3D, SDK 5; 1 = "
                   "linear)"),
        floatParam("distance_exponent", 50.0, 1.0, 200.0, "",
                   "cosine power of the distance blend (G3D, SDK 50)"),
        floatParam("max_distance_factor", 1.5, 0.1, 10.0, "cell diagonals",
                   "stored distances are clamped to this x the cell diagonal (G3D 1.5)"),
        enumParam("bias_mode", "self_shadow", {"self_shadow", "normal_view"},
                  "query bias: self_shadow = (0.2 n + 0.8 w_o) 0.75 d_min b (paper 2, G3D) | "
                  "normal_view = b_n n + b_v w_o in world units (SDK)"),
        floatParam("self_shadow_bias", 0.3, 0.0, 2.0, "", "b of the self_shadow bias (G3D 0.3)"),
        floatParam("normal_bias", 0.1, 0.0, 10.0, "m", "b_n of the normal_view bias (SDK 0.1)"),
        floatParam("view_bias", 0.1, 0.0, 10.0, "m", "b_v of the normal_view bias (SDK 0.1)"),
        floatParam("chebyshev_floor", 0.05, 0.0, 1.0, "",
                   "lower bound of the Chebyshev visibility weight (SDK 0.05; paper-era code 0)"),
        allowValue(-1, intParam("bounces", -1, 1, 1, "",
                                "-1 = unbounded bounces by feeding the previous irradiance to "
                                "the probe-ray hits (the paper); 1 = probe-ray hits see direct "
                                "light only")),
        boolParam("emission_in_probes", false,
                  "add the emission of surfaces the probe rays hit (the papers); off by default "
                  "because the shared direct layer already carries emitters' direct light "
                  "(on: counted twice; for the furnace test)"),
        intParam("hit_light_samples", 4, 1, 256, "samples",
                 "emitter samples (area lights) shaded per probe-ray hit, chosen at random with "
                 "a shadow ray each; punctual lights are all shaded"),
        floatParam("hit_texture_lod", 0.0, 0.0, 12.0, "mip",
                   "texture mip level at probe-ray hits (blog: a bias of about 5)"),
        floatParam("energy_preservation", 1.0, 0.5, 1.0, "",
                   "damping of the feedback irradiance at probe-ray hits (paper-era code 0.85; "
                   "1 = none)"),
        floatParam("irradiance_threshold", 0.0, 0.0, 10.0, "",
                   "SDK heuristic: hysteresis - 0.75 where a texel changes by more (encoded); "
                   "0 = off (SDK 0.25)"),
        floatParam("brightness_threshold", 0.0, 0.0, 10.0, "",
                   "SDK heuristic: steps brighter than this (encoded luminance) are cut to 1/4; "
                   "0 = off (SDK 0.10)"),
        floatParam("backface_threshold", 0.25, 0.0, 1.0, "",
                   "fixed-ray back-face share above which a probe is inside geometry (SDK 0.25)"),
        floatParam("random_backface_threshold", 0.1, 0.0, 1.0, "",
                   "back-face share above which the irradiance blend leaves a probe's texels "
                   "unchanged (SDK 0.1)"),
        floatParam("min_frontface_distance", 0.2, 0.0, 1.0, "min spacings",
                   "relocation keeps probes this far from front faces (SDK 1.0 world units; here "
                   "a fraction of the spacing)"),
        intParam("event_frames", 0, 0, 64, "frames",
                 "frames at half hysteresis after a light change (G3D onGlobalLightChange: 10; "
                 "0 = off)"),
        enumParam("warm_start", "ramp", {"ramp", "paper"},
                  "cold start: ramp = hysteresis min(alpha, k / (k + 4)) on update k until the "
                  "probes first settle (techniques/ddgi/README.md) | paper = alpha 0 on the "
                  "first update, then alpha"),
        floatParam("settle_tolerance", 0.005, 1e-5, 0.5, "",
                   "warm-up ends when the estimated remaining relative change of the mean "
                   "irradiance is below this"),
        intParam("seed", 1, 0, 1 << 30, "", "seed of the per-frame random ray rotations"),
    };
}

DdgiSettings ddgiSettingsFrom(const ParamSet& p) {
    DdgiSettings s;
    s.probeGrid = p.getInt("probe_grid");
    s.probeCounts = glm::ivec3(p.getInt("probes_x"), p.getInt("probes_y"), p.getInt("probes_z"));
    s.volumeScale = p.getFloat("volume_scale");
    s.raysPerProbe = p.getInt("rays_per_probe");
    s.irradianceTexels = p.getInt("irradiance_texels");
    s.distanceTexels = p.getInt("distance_texels");
    s.relocation = p.getBool("relocation");
    s.classification = p.getBool("classification");
    if (s.fixedRays() > 0 && s.raysPerProbe < s.fixedRays() + 8)
        throw Error("ddgi: rays_per_probe = " + std::to_string(s.raysPerProbe) +
                    " leaves fewer than 8 blended rays beside the 32 fixed rays of relocation / "
                    "classification; use at least 40 or turn both off");
    s.hysteresis = p.getFloat("hysteresis");
    s.irradianceGamma = p.getFloat("irradiance_gamma");
    s.distanceExponent = p.getFloat("distance_exponent");
    s.maxDistanceFactor = p.getFloat("max_distance_factor");
    s.biasMode =
        p.getEnum("bias_mode") == "normal_view" ? DdgiBias::NormalView : DdgiBias::SelfShadow;
    s.selfShadowBias = p.getFloat("self_shadow_bias");
    s.normalBias = p.getFloat("normal_bias");
    s.viewBias = p.getFloat("view_bias");
    s.chebyshevFloor = p.getFloat("chebyshev_floor");
    s.feedback = p.getInt("bounces") < 0;
    s.emissionInProbes = p.getBool("emission_in_probes");
    s.hitLightSamples = p.getInt("hit_light_samples");
    s.hitTextureLod = p.getFloat("hit_texture_lod");
    s.energyPreservation = p.getFloat("energy_preservation");
    s.irradianceThreshold = p.getFloat("irradiance_threshold");
    s.brightnessThreshold = p.getFloat("brightness_threshold");
    s.backfaceThreshold = p.getFloat("backface_threshold");
    s.randomBackfaceThreshold = p.getFloat("random_backface_threshold");
    s.minFrontfaceDistance = p.getFloat("min_frontface_distance");
    s.eventFrames = p.getInt("event_frames");
    s.warmStart = p.getEnum("warm_start") == "paper" ? DdgiWarmStart::Paper : DdgiWarmStart::Ramp;
    s.settleTolerance = p.getFloat("settle_tolerance");
    s.seed = uint32_t(p.getInt("seed"));
    return s;
}

}  // namespace gilab
