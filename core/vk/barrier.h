#pragma once
/** Coarse synchronization2 barriers. We favour correctness over overlap at our scale. */
#include <vulkan/vulkan.h>

namespace gilab::vk {

class Buffer;

/** All commands -> all commands, all memory writes visible to all reads/writes. */
void memoryBarrier(VkCommandBuffer cmd);
/** All commands -> host reads (before mapping results written by the device). */
void hostReadBarrier(VkCommandBuffer cmd);
/** Same, scoped to one buffer. */
void bufferBarrier(VkCommandBuffer cmd, const Buffer& buffer);

}  // namespace gilab::vk
