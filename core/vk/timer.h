#pragma once
/**
 * GPU timestamp profiling per named pass. Usage per frame:
 *   timer.reset(cmd);  { ScopedGpuPass p(timer, cmd, "gbuffer"); ... }  submit+wait;
 *   auto times = timer.resolve();
 * A name used more than once in a frame is summed. Without timestamp support gpuMs = NaN.
 */
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "core/vk/handle.h"

namespace gilab::vk {

class Context;

struct PassTime {
    std::string name;
    double gpuMs = 0.0;        // NaN when timestamps are unsupported
    double cpuRecordMs = 0.0;  // time spent recording between begin() and end()
};

class GpuTimer {
public:
    GpuTimer(Context& ctx, uint32_t maxPasses = 64);
    /** At the start of the frame's command buffer: vkCmdResetQueryPool, forget old passes. */
    void reset(VkCommandBuffer cmd);
    void begin(VkCommandBuffer cmd, const std::string& name);
    void end(VkCommandBuffer cmd);
    /** After the submission completed. Order = first begin() of each name. */
    std::vector<PassTime> resolve();
    bool supported() const { return m_supported; }
    /** Why gpuMs is NaN, or empty. */
    const std::string& note() const { return m_note; }

private:
    /** Writes a timestamp into `query`, then one into the spare query (see timer.cpp). */
    void stamp(VkCommandBuffer cmd, uint32_t query);

    struct Open {
        std::string name;
        uint32_t query;
        std::chrono::steady_clock::time_point cpuStart;
        double cpuMs = 0.0;
    };
    Context* m_ctx;
    uint32_t m_maxPasses;
    bool m_supported;
    std::string m_note;
    QueryPoolHandle m_pool;
    std::vector<Open> m_passes;
    std::vector<size_t> m_stack;  // open pass indices (nesting allowed)
};

class ScopedGpuPass {
public:
    ScopedGpuPass(GpuTimer& timer, VkCommandBuffer cmd, std::string name);
    ~ScopedGpuPass();
    ScopedGpuPass(const ScopedGpuPass&) = delete;
    ScopedGpuPass& operator=(const ScopedGpuPass&) = delete;

private:
    GpuTimer& m_timer;
    VkCommandBuffer m_cmd;
};

}  // namespace gilab::vk
