#pragma once
/** The cost of the timing instrumentation itself, measured once per experiment (docs/timing.md). */
#include <nlohmann/json.hpp>

#include "core/scene/scene.h"

namespace gilab {
namespace vk {
class Context;
}
namespace exp {

/**
 * Renders `frames` frames of the `direct` baseline with GPU timestamp queries and as many
 * without, interleaved, and reports the median CPU frame time of each and their difference.
 */
nlohmann::ordered_json measureInstrumentationOverhead(vk::Context& vk, const Scene& scene,
                                                      int frames = 8);

}  // namespace exp
}  // namespace gilab
