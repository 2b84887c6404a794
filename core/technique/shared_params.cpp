// The shared passes' parameter table (owner "shared"; --set shared.<key>=value).
#include "core/passes/shared_passes.h"
#include "core/technique/frame_harness.h"
#include "core/util/error.h"

namespace gilab {

std::vector<ParamSpec> sharedPassParamSpecs() {
    const ShadowSettings d;
    const SharedPassSettings s;
    return {
        boolParam("shadows", d.enabled, "Shadow maps on (off: every light is unoccluded)",
                  ParamStage::Rebuild),
        intParam("shadow_resolution", int(d.resolution), 16, 8192, "texels",
                 "Side of each 2D shadow map, cascade and point-light cube face",
                 ParamStage::Rebuild),
        intParam("area_shadow_resolution", int(d.areaResolution), 16, 4096, "texels",
                 "Side of each emitter-sample cube face", ParamStage::Rebuild),
        intParam("pcf_radius", d.pcfRadius, 0, 8, "texels",
                 "PCF kernel radius, (2r+1)^2 taps; 0 = hard shadows", ParamStage::Rebuild),
        floatParam("shadow_constant_bias", d.constantBias, 0.0, 64.0, "texels",
                   "Constant depth bias (direct pass)", ParamStage::Rebuild),
        floatParam("shadow_slope_bias", d.slopeBias, 0.0, 64.0, "texels",
                   "Depth bias per unit tan(angle to the light) (direct pass)",
                   ParamStage::Rebuild),
        floatParam("shadow_normal_offset", d.normalOffset, 0.0, 64.0, "texels",
                   "Receiver offset along its normal, in texels per (pcf_radius + 1) (direct "
                   "pass)",
                   ParamStage::Rebuild),
        boolParam("shadow_receiver_plane", d.receiverPlane,
                  "Compare each shadow-map texel with the receiver triangle's plane along the "
                  "texel's ray (off: only the biases above)",
                  ParamStage::Rebuild),
        intParam("shadow_cascades", int(d.cascades), 0, 8, "",
                 "View-fitted shadow maps per directional light (0 = the whole-scene map only)",
                 ParamStage::Rebuild),
        floatParam("shadow_cascade_split", d.cascadeSplit, 0.0, 1.0, "",
                   "Cascade split scheme: 0 uniform in depth, 1 logarithmic", ParamStage::Rebuild),
        boolParam("shadow_cascade_snap", d.cascadeSnap,
                  "Cascade sizes in quarter-octave steps and centres on whole texels, so the "
                  "texel grid stays put when the camera moves (off: refit exactly, edges crawl)",
                  ParamStage::Rebuild),
        floatParam("shadow_cascade_blend", d.cascadeBlend, 0.0, 0.5, "",
                   "Band at each cascade's border (fraction of its half-size) where a receiver's "
                   "visibility fades linearly into the next cascade's (0 = a hard switch)",
                   ParamStage::Rebuild),
        intParam("area_light_samples", int(s.areaLightSamples), 0, 4096, "",
                 "Virtual point lights standing in for emissive surfaces in the direct pass "
                 "(0 = emitters light nothing directly)",
                 ParamStage::Rebuild),
        boolParam("area_light_analytic", s.areaLightAnalytic,
                  "Direct pass: the emissive triangles' unoccluded irradiance is exact (Lambert's "
                  "polygon formula) and the samples give its visible share (off: the samples' "
                  "sum alone)",
                  ParamStage::Rebuild),
    };
}

namespace {
// Emitter-sample cubes: K cubes x 6 faces x res^2 x (R32F distance + D32 depth).
constexpr double kMaxAreaShadowBytes = 4.0 * 1024 * 1024 * 1024;
}  // namespace

ParamSet defaultSharedParams() {
    return ParamSet(sharedPassParamSpecs(), "shared");
}

SharedPassSettings sharedSettingsFromParams(const ParamSet& p) {
    SharedPassSettings s;
    s.shadow.enabled = p.getBool("shadows");
    s.shadow.resolution = uint32_t(p.getInt("shadow_resolution"));
    s.shadow.areaResolution = uint32_t(p.getInt("area_shadow_resolution"));
    s.shadow.pcfRadius = p.getInt("pcf_radius");
    s.shadow.constantBias = p.getFloat("shadow_constant_bias");
    s.shadow.slopeBias = p.getFloat("shadow_slope_bias");
    s.shadow.normalOffset = p.getFloat("shadow_normal_offset");
    s.shadow.receiverPlane = p.getBool("shadow_receiver_plane");
    s.shadow.cascades = uint32_t(p.getInt("shadow_cascades"));
    s.shadow.cascadeSplit = p.getFloat("shadow_cascade_split");
    s.shadow.cascadeSnap = p.getBool("shadow_cascade_snap");
    s.shadow.cascadeBlend = p.getFloat("shadow_cascade_blend");
    s.areaLightSamples = uint32_t(p.getInt("area_light_samples"));
    s.areaLightAnalytic = p.getBool("area_light_analytic");
    const double res = double(s.shadow.areaResolution);
    const double bytes = double(s.areaLightSamples) * 6.0 * res * res * 8.0;
    if (s.shadow.enabled && bytes > kMaxAreaShadowBytes)
        throw Error(
            "shared.area_light_samples=" + std::to_string(s.areaLightSamples) +
            " with shared.area_shadow_resolution=" + std::to_string(s.shadow.areaResolution) +
            " needs " + std::to_string(int(bytes / (1024.0 * 1024.0))) +
            " MiB of shadow cubes (limit 4096 MiB); lower one of them");
    return s;
}

}  // namespace gilab
