#pragma once
/**
 * The VPL clustering and propagation steps of `ssvp` (Aranha et al. §III-B, §III-C), on the GPU.
 * Each step runs on one VPL range: First = the N1 first-bounce VPLs in clusters [0, C); Second =
 * with second_bounce_visibility = own_maps (ours), the N2 second-bounce VPLs in clusters
 * [C, C + C2), whose maps are layers C.. of the same paraboloid array.
 *   recordClustering      K-means over the range's VPLs: seed (first frame), then per
 *                         iteration an assignment dispatch and an update dispatch
 *                         (techniques/ssvp/shaders/kmeans_*.comp), warm-started from the previous
 * frame's centroids, stopping on convergence or after the iteration cap recordMembers         after
 * the maps: does each cluster's map see its members (map_members.comp; with map_members = reassign,
 * unseen members move to a map that sees them and cluster_flux.comp re-sums the fluxes)
 *   recordSecondBounce    N2 / C VPLs per cluster from its paraboloid map (second_bounce.comp)
 * readState() gives the last frame's iteration count and re-seeded clusters once it finished.
 */
#include <cstdint>
#include <string>

#include <vulkan/vulkan.h>

#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/pipeline.h"
#include "ssvp_settings.h"

namespace gilab {

enum class SsvpRange { First = 0, Second = 1 };
namespace vk {
class Context;
}  // namespace vk
class ParaboloidMaps;

struct SsvpKmeansState {
    uint32_t iterations = 0;  // update passes run in the last frame
    bool converged = false;
    uint32_t reseeded = 0;  // empty clusters re-seeded in the last frame
    uint32_t active = 0;    // clusters with members (paraboloid maps rendered)
    uint32_t assigned = 0;  // valid first-bounce VPLs in them
};

/** What map_members.comp found in the last frame (shares of the clustered members' flux). */
struct SsvpMemberStats {
    double seenPercent = 0.0;       // seen by their own cluster's map
    double seenAfterPercent = 0.0;  // seen by the map they are shaded with (after a move)
    double movedPercent = 0.0;      // moved to another cluster (map_members = reassign)
};

class SsvpPropagation {
public:
    SsvpPropagation(vk::Context& ctx, const vk::Buffer& vpls, const vk::Buffer& clusters,
                    ParaboloidMaps& maps, const std::string& tag);
    SsvpPropagation(const SsvpPropagation&) = delete;
    SsvpPropagation& operator=(const SsvpPropagation&) = delete;

    /** sceneDiagonal: the unit of the position term of Eq. 2 and of the eye offset. */
    void setSettings(const SsvpSettings& settings, float sceneDiagonal);
    void recordClustering(VkCommandBuffer cmd, SsvpRange range);
    void recordMembers(VkCommandBuffer cmd, SsvpRange range);
    void recordSecondBounce(VkCommandBuffer cmd);
    SsvpKmeansState readState(SsvpRange range);
    SsvpMemberStats readMemberStats(SsvpRange range);

private:
    struct Push {  // mirrors KmeansPush in techniques/ssvp/shaders/kmeans_common.glsl
        float positionWeight, normalWeight, invDiagonal, eyeOffset;
        uint32_t count, clusterCount, iteration, metric, seed, secondCount, perCluster,
            paperWeights, secondVisibility, mapResolution, eyeAtVpl, reassign;
        float biasTexels;
        uint32_t vplBase, clusterBase;
    };
    /** Binds the pipeline, the range's descriptor set (its K-means state) and push constants. */
    const Push& bind(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline, SsvpRange range);

    SsvpSettings m_settings;
    Push m_push[2]{};
    vk::Buffer m_state[2], m_members;
    vk::DescriptorSetLayout m_setLayout;
    vk::DescriptorSet m_set[2];
    vk::PipelineLayout m_layout;
    vk::ComputePipeline m_seed, m_assign, m_update, m_second, m_memberTest, m_clusterFlux;
};

}  // namespace gilab
