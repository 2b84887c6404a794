#include "core/vk/timer.h"

#include <cmath>
#include <limits>
#include <map>

#include "core/util/error.h"
#include "core/vk/check.h"
#include "core/vk/context.h"

namespace gilab::vk {

GpuTimer::GpuTimer(Context& ctx, uint32_t maxPasses)
    : m_ctx(&ctx), m_maxPasses(maxPasses), m_supported(ctx.timestampsSupported()) {
    if (!m_supported) {
        m_note = "timestamps unsupported on " + ctx.deviceName() + "; GPU times are NaN";
        return;
    }
    VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    info.queryCount = 4 * maxPasses;  // begin, end, and a spare of each for stamp()
    VkQueryPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkCreateQueryPool(ctx.device(), &info, nullptr, &pool));
    m_pool = QueryPoolHandle(ctx.device(), pool);
    ctx.setDebugName(VK_OBJECT_TYPE_QUERY_POOL, uint64_t(pool), "timer/queries");
    // Host reset so a resolve() before the first reset(cmd) reads "not available", not garbage.
    vkResetQueryPool(ctx.device(), pool, 0, 4 * maxPasses);
}

void GpuTimer::stamp(VkCommandBuffer cmd, uint32_t query) {
    vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, m_pool.handle(), query);
    // Lavapipe (Mesa 22.3) takes a timestamp's value at the next flush of its context, and only
    // a later timestamp write or a command that reads GPU memory on the host (an indirect
    // dispatch, a draw) flushes: a compute dispatch between two stamps was counted in neither.
    // A second write to a spare query (one per query: each is written once between resets)
    // flushes right after this one. Measured: a VPL gather dispatch of 480 ms (issue 14) read
    // 0.2 ms without it. Harmless elsewhere.
    vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, m_pool.handle(),
                         2 * m_maxPasses + query);
}

void GpuTimer::reset(VkCommandBuffer cmd) {
    m_passes.clear();
    m_stack.clear();
    if (m_supported) vkCmdResetQueryPool(cmd, m_pool.handle(), 0, 4 * m_maxPasses);
}

void GpuTimer::begin(VkCommandBuffer cmd, const std::string& name) {
    if (m_passes.size() >= m_maxPasses) {
        throw Error("GpuTimer: more than " + std::to_string(m_maxPasses) +
                    " passes in one frame (raise maxPasses)");
    }
    uint32_t query = uint32_t(2 * m_passes.size());
    m_passes.push_back({name, query, std::chrono::steady_clock::now(), 0.0});
    m_stack.push_back(m_passes.size() - 1);
    if (m_supported) stamp(cmd, query);
}

void GpuTimer::end(VkCommandBuffer cmd) {
    if (m_stack.empty()) throw Error("GpuTimer::end without a matching begin");
    Open& pass = m_passes[m_stack.back()];
    m_stack.pop_back();
    if (m_supported) stamp(cmd, pass.query + 1);
    pass.cpuMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - pass.cpuStart)
            .count();
}

std::vector<PassTime> GpuTimer::resolve() {
    if (!m_stack.empty())
        throw Error("GpuTimer::resolve with pass '" + m_passes[m_stack.back()].name +
                    "' still open");
    std::vector<uint64_t> stamps;
    if (m_supported && !m_passes.empty()) {
        stamps.resize(2 * m_passes.size() * 2);  // (value, availability) pairs
        VkResult result = vkGetQueryPoolResults(
            m_ctx->device(), m_pool.handle(), 0, uint32_t(2 * m_passes.size()),
            stamps.size() * sizeof(uint64_t), stamps.data(), 2 * sizeof(uint64_t),
            VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT);
        if (result != VK_NOT_READY) VK_CHECK(result);  // NOT_READY: some passes lack results
    }
    uint32_t bits = m_ctx->timestampValidBits();
    uint64_t mask = bits >= 64 ? ~0ull : ((1ull << bits) - 1);
    double period = m_ctx->timestampPeriodNs();

    std::vector<PassTime> out;
    std::map<std::string, size_t> index;
    for (size_t i = 0; i < m_passes.size(); ++i) {
        const Open& p = m_passes[i];
        double gpuMs = std::numeric_limits<double>::quiet_NaN();
        if (m_supported) {
            uint64_t t0 = stamps[4 * i] & mask, a0 = stamps[4 * i + 1];
            uint64_t t1 = stamps[4 * i + 2] & mask, a1 = stamps[4 * i + 3];
            if (a0 && a1) {
                uint64_t ticks = (t1 - t0) & mask;  // wraps within the valid bits
                gpuMs = double(ticks) * period * 1e-6;
            }
        }
        auto it = index.find(p.name);
        if (it == index.end()) {
            index.emplace(p.name, out.size());
            out.push_back({p.name, gpuMs, p.cpuMs});
        } else {
            out[it->second].gpuMs += gpuMs;
            out[it->second].cpuRecordMs += p.cpuMs;
        }
    }
    return out;
}

ScopedGpuPass::ScopedGpuPass(GpuTimer& timer, VkCommandBuffer cmd, std::string name)
    : m_timer(timer), m_cmd(cmd) {
    m_timer.begin(cmd, name);
}

ScopedGpuPass::~ScopedGpuPass() {
    m_timer.end(m_cmd);
}

}  // namespace gilab::vk
