#include "direct.h"

#include "core/technique/registry.h"

namespace gilab {

TechniqueInfo DirectTechnique::describe() {
    TechniqueInfo info;
    info.id = "direct";
    info.description = "Direct light only (shared G-buffer, shadow maps, direct pass); no GI";
    info.indirectBounces = 0;
    return info;
}

void DirectTechnique::setup(TechniqueContext& ctx) {
    ctx.note("baseline: indirect layer is zero by construction");
}

UpdateKind DirectTechnique::update(TechniqueContext&, const SceneChanges&) {
    return UpdateKind::None;
}

void DirectTechnique::render(TechniqueContext&, VkCommandBuffer, FrameTargets&) {
    // Nothing to add: the harness clears the indirect layer and runs the shared direct pass.
}

GILAB_REGISTER_TECHNIQUE(DirectTechnique)

}  // namespace gilab
