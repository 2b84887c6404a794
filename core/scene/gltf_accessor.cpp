#include "core/scene/gltf_accessor.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <tiny_gltf.h>

#include "core/util/error.h"

namespace gilab::gltf {

namespace {

/** One component as a double; normalized integers map to [0, 1] or [-1, 1] (glTF 3.11). */
double readComponent(const uint8_t* p, int componentType, bool normalized) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            const int8_t v = int8_t(*p);
            return normalized ? std::max(double(v) / 127.0, -1.0) : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return normalized ? double(*p) / 255.0 : double(*p);
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            int16_t v;
            std::memcpy(&v, p, sizeof v);
            return normalized ? std::max(double(v) / 32767.0, -1.0) : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t v;
            std::memcpy(&v, p, sizeof v);
            return normalized ? double(v) / 65535.0 : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_INT: {
            int32_t v;
            std::memcpy(&v, p, sizeof v);
            return double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            uint32_t v;
            std::memcpy(&v, p, sizeof v);
            return double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
            float v;
            std::memcpy(&v, p, sizeof v);
            return double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: {
            double v;
            std::memcpy(&v, p, sizeof v);
            return v;
        }
        default:
            return 0.0;
    }
}

/** Start of the data of `viewIndex` plus `byteOffset`, checking `size` bytes are in bounds. */
const uint8_t* viewData(const tinygltf::Model& model, int viewIndex, size_t byteOffset, size_t size,
                        const std::string& what) {
    if (viewIndex < 0 || size_t(viewIndex) >= model.bufferViews.size()) {
        throw Error(what + ": bufferView " + std::to_string(viewIndex) + " does not exist");
    }
    const tinygltf::BufferView& view = model.bufferViews[size_t(viewIndex)];
    if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size()) {
        throw Error(what + ": bufferView " + std::to_string(viewIndex) + " has no buffer");
    }
    const tinygltf::Buffer& buffer = model.buffers[size_t(view.buffer)];
    if (view.byteOffset + view.byteLength > buffer.data.size() ||
        byteOffset + size > view.byteLength) {
        throw Error(what + ": data runs past the end of bufferView " + std::to_string(viewIndex) +
                    " or its buffer (truncated .bin?)");
    }
    return buffer.data.data() + view.byteOffset + byteOffset;
}

/** All components of an accessor as doubles, `count * components` values, sparse applied. */
std::vector<double> readRaw(const tinygltf::Model& model, int index, int components,
                            const std::string& what) {
    if (index < 0 || size_t(index) >= model.accessors.size()) {
        throw Error(what + ": accessor " + std::to_string(index) + " does not exist");
    }
    const tinygltf::Accessor& acc = model.accessors[size_t(index)];
    const std::string name = what + " (accessor " + std::to_string(index) + ")";
    const int compSize = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
    if (compSize <= 0) {
        throw Error(name + ": unknown componentType " + std::to_string(acc.componentType));
    }
    if (tinygltf::GetNumComponentsInType(uint32_t(acc.type)) != components) {
        throw Error(name + ": expected " + std::to_string(components) +
                    " components per element, got accessor type " + std::to_string(acc.type));
    }
    const size_t elemSize = size_t(compSize) * size_t(components);
    std::vector<double> out(acc.count * size_t(components), 0.0);

    // Dense part (an accessor without a bufferView is all zeros).
    if (acc.bufferView >= 0 && acc.count > 0) {
        const auto& view = model.bufferViews.at(size_t(acc.bufferView));
        const size_t stride = view.byteStride ? view.byteStride : elemSize;
        const size_t span = stride * (acc.count - 1) + elemSize;
        const uint8_t* base = viewData(model, acc.bufferView, acc.byteOffset, span, name);
        for (size_t i = 0; i < acc.count; ++i) {
            for (int c = 0; c < components; ++c) {
                out[i * size_t(components) + size_t(c)] =
                    readComponent(base + i * stride + size_t(c) * size_t(compSize),
                                  acc.componentType, acc.normalized);
            }
        }
    }

    // Sparse substitution: `count` (index, value) pairs, both tightly packed.
    if (acc.sparse.isSparse) {
        const auto& sp = acc.sparse;
        const int idxSize = tinygltf::GetComponentSizeInBytes(uint32_t(sp.indices.componentType));
        if (idxSize <= 0 || sp.count < 0) throw Error(name + ": malformed sparse accessor");
        const size_t n = size_t(sp.count);
        const uint8_t* idx = viewData(model, sp.indices.bufferView, size_t(sp.indices.byteOffset),
                                      n * size_t(idxSize), name + " sparse indices");
        const uint8_t* val = viewData(model, sp.values.bufferView, size_t(sp.values.byteOffset),
                                      n * elemSize, name + " sparse values");
        for (size_t k = 0; k < n; ++k) {
            const double target =
                readComponent(idx + k * size_t(idxSize), sp.indices.componentType, false);
            if (target < 0 || target >= double(acc.count)) {
                throw Error(name + ": sparse index " + std::to_string(int64_t(target)) +
                            " out of range (count " + std::to_string(acc.count) + ")");
            }
            for (int c = 0; c < components; ++c) {
                out[size_t(target) * size_t(components) + size_t(c)] =
                    readComponent(val + k * elemSize + size_t(c) * size_t(compSize),
                                  acc.componentType, acc.normalized);
            }
        }
    }
    return out;
}

}  // namespace

std::vector<float> readFloats(const tinygltf::Model& model, int index, int components,
                              const std::string& what) {
    const std::vector<double> raw = readRaw(model, index, components, what);
    return std::vector<float>(raw.begin(), raw.end());
}

std::vector<uint32_t> readIndices(const tinygltf::Model& model, int index,
                                  const std::string& what) {
    const std::vector<double> raw = readRaw(model, index, 1, what + " indices");
    const int type = model.accessors[size_t(index)].componentType;
    if (type == TINYGLTF_COMPONENT_TYPE_FLOAT || type == TINYGLTF_COMPONENT_TYPE_DOUBLE) {
        throw Error(what + ": indices must be integers (accessor " + std::to_string(index) + ")");
    }
    std::vector<uint32_t> out(raw.size());
    for (size_t i = 0; i < raw.size(); ++i) {
        if (raw[i] < 0 || raw[i] > 4294967295.0) {
            throw Error(what + ": index " + std::to_string(int64_t(raw[i])) + " at position " +
                        std::to_string(i) + " is out of range");
        }
        out[i] = uint32_t(raw[i]);
    }
    return out;
}

}  // namespace gilab::gltf
