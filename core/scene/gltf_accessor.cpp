#include "core/scene/gltf_accessor.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <tiny_gltf.h>

#include "core/util/error.h"

namespace gilab::gltf {

namespace {

std::string str(size_t v) {
    return std::to_string(v);
}

const char* componentTypeName(int type) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
            return "BYTE";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return "UNSIGNED_BYTE";
        case TINYGLTF_COMPONENT_TYPE_SHORT:
            return "SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return "UNSIGNED_SHORT";
        case TINYGLTF_COMPONENT_TYPE_INT:
            return "INT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
            return "UNSIGNED_INT";
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
            return "FLOAT";
        case TINYGLTF_COMPONENT_TYPE_DOUBLE:
            return "DOUBLE";
        default:
            return "unknown";
    }
}

const char* typeName(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR:
            return "SCALAR";
        case TINYGLTF_TYPE_VEC2:
            return "VEC2";
        case TINYGLTF_TYPE_VEC3:
            return "VEC3";
        case TINYGLTF_TYPE_VEC4:
            return "VEC4";
        case TINYGLTF_TYPE_MAT2:
            return "MAT2";
        case TINYGLTF_TYPE_MAT3:
            return "MAT3";
        case TINYGLTF_TYPE_MAT4:
            return "MAT4";
        default:
            return "unknown";
    }
}

const char* componentsName(int components) {
    static const char* names[] = {"?", "SCALAR", "VEC2", "VEC3", "VEC4"};
    return components >= 1 && components <= 4 ? names[components] : "?";
}

bool isUnsignedInteger(int componentType) {
    return componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
           componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
           componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
}

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

/** An unsigned integer component (UNSIGNED_BYTE / _SHORT / _INT) as is. */
uint32_t readUnsigned(const uint8_t* p, int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return *p;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t v;
            std::memcpy(&v, p, sizeof v);
            return v;
        }
        default: {
            uint32_t v;
            std::memcpy(&v, p, sizeof v);
            return v;
        }
    }
}

/** a * b + c without wrapping; false on overflow. */
bool mulAdd(size_t a, size_t b, size_t c, size_t& out) {
    size_t product = 0;
    return !__builtin_mul_overflow(a, b, &product) && !__builtin_add_overflow(product, c, &out);
}

/** bufferView `viewIndex`, checked to exist and to lie inside an existing buffer. */
const tinygltf::BufferView& checkedView(const tinygltf::Model& model, int viewIndex,
                                        const std::string& name) {
    if (viewIndex < 0 || size_t(viewIndex) >= model.bufferViews.size()) {
        throw Error(name + ": bufferView " + std::to_string(viewIndex) +
                    " does not exist (the file has " + str(model.bufferViews.size()) +
                    " bufferViews)");
    }
    const tinygltf::BufferView& view = model.bufferViews[size_t(viewIndex)];
    const std::string label = "bufferView " + std::to_string(viewIndex);
    if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size()) {
        throw Error(name + ": " + label + " references buffer " + std::to_string(view.buffer) +
                    ", which does not exist (the file has " + str(model.buffers.size()) +
                    " buffers)");
    }
    const size_t bufferSize = model.buffers[size_t(view.buffer)].data.size();
    size_t end = 0;
    if (!mulAdd(view.byteOffset, 1, view.byteLength, end) || end > bufferSize) {
        throw Error(name + ": " + label + " (byteOffset " + str(view.byteOffset) + ", byteLength " +
                    str(view.byteLength) + ") runs past the end of buffer " +
                    std::to_string(view.buffer) + " (" + str(bufferSize) +
                    " bytes; truncated .bin?)");
    }
    return view;
}

/** `size` tightly packed bytes at `offset` in bufferView `viewIndex`, bounds checked. */
const uint8_t* packedBytes(const tinygltf::Model& model, int viewIndex, size_t offset, size_t count,
                           size_t elemSize, const std::string& name) {
    const tinygltf::BufferView& view = checkedView(model, viewIndex, name);
    size_t end = 0;
    if (!mulAdd(count, elemSize, offset, end) || end > view.byteLength) {
        throw Error(name + ": " + str(count) + " elements of " + str(elemSize) +
                    " bytes from byteOffset " + str(offset) + " do not fit bufferView " +
                    std::to_string(viewIndex) + " (byteLength " + str(view.byteLength) + ")");
    }
    return model.buffers[size_t(view.buffer)].data.data() + view.byteOffset + offset;
}

/** Where an accessor's values are, everything checked; nothing of `count` size allocated. */
struct Source {
    const tinygltf::Accessor* acc = nullptr;
    std::string name;  // "<what> (accessor N)"
    int components = 0;
    size_t compSize = 0;
    size_t elemSize = 0;
    const uint8_t* dense = nullptr;  // null: all zeros
    size_t stride = 0;
    size_t sparseCount = 0;
    const uint8_t* sparseIndices = nullptr;
    int sparseIndexType = 0;
    size_t sparseIndexSize = 0;
    const uint8_t* sparseValues = nullptr;
};

Source prepare(const tinygltf::Model& model, int index, int components, const std::string& what) {
    if (index < 0 || size_t(index) >= model.accessors.size()) {
        throw Error(what + ": accessor " + std::to_string(index) +
                    " does not exist (the file has " + str(model.accessors.size()) + " accessors)");
    }
    Source s;
    s.acc = &model.accessors[size_t(index)];
    const tinygltf::Accessor& acc = *s.acc;
    s.name = what + " (accessor " + std::to_string(index) +
             (acc.name.empty() ? "" : " '" + acc.name + "'") + ")";
    const int compSize = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
    if (compSize <= 0) {
        throw Error(s.name + ": unknown componentType " + std::to_string(acc.componentType));
    }
    if (tinygltf::GetNumComponentsInType(uint32_t(acc.type)) != components) {
        throw Error(s.name + ": type " + typeName(acc.type) + " where " +
                    componentsName(components) + " is required");
    }
    s.components = components;
    s.compSize = size_t(compSize);
    s.elemSize = s.compSize * size_t(components);

    // Dense part: the declared count must fit the view before anything is allocated
    if (acc.bufferView != -1) {
        const tinygltf::BufferView& view = checkedView(model, acc.bufferView, s.name);
        const std::string label = "bufferView " + std::to_string(acc.bufferView);
        if (view.byteStride != 0 && view.byteStride < s.elemSize) {
            throw Error(s.name + ": " + label + " byteStride " + str(view.byteStride) +
                        " is smaller than the element size (" + str(s.elemSize) + " bytes, " +
                        typeName(acc.type) + " of " + componentTypeName(acc.componentType) + ")");
        }
        s.stride = view.byteStride != 0 ? view.byteStride : s.elemSize;
        size_t end = acc.byteOffset;
        const bool overflow = acc.count > 0 && !(mulAdd(acc.count - 1, s.stride, s.elemSize, end) &&
                                                 mulAdd(end, 1, acc.byteOffset, end));
        if (overflow || end > view.byteLength) {
            throw Error(s.name + ": count " + str(acc.count) + " does not fit " + label + ": " +
                        str(acc.count) + " elements of " + str(s.elemSize) + " bytes (stride " +
                        str(s.stride) + ") from byteOffset " + str(acc.byteOffset) + " need " +
                        (overflow ? std::string("more than 2^64") : str(end)) +
                        " bytes, the view has " + str(view.byteLength));
        }
        if (acc.count > 0) {
            s.dense =
                model.buffers[size_t(view.buffer)].data.data() + view.byteOffset + acc.byteOffset;
        }
    } else if (acc.count > kMaxUnbackedElements) {
        throw Error(s.name + ": count " + str(acc.count) +
                    " with no bufferView (all zeros) exceeds the limit of " +
                    str(kMaxUnbackedElements) + " elements");
    }

    // Sparse substitution: `count` (index, value) pairs, both tightly packed
    if (acc.sparse.isSparse) {
        const auto& sp = acc.sparse;
        if (sp.count < 1 || size_t(sp.count) > acc.count) {
            throw Error(s.name + ": sparse count " + std::to_string(sp.count) + " must be in [1, " +
                        str(acc.count) + "] (the accessor's count)");
        }
        if (!isUnsignedInteger(sp.indices.componentType)) {
            throw Error(s.name + ": sparse indices have componentType " +
                        componentTypeName(sp.indices.componentType) +
                        "; UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT is required");
        }
        s.sparseCount = size_t(sp.count);
        s.sparseIndexType = sp.indices.componentType;
        s.sparseIndexSize =
            size_t(tinygltf::GetComponentSizeInBytes(uint32_t(sp.indices.componentType)));
        if (sp.indices.byteOffset < 0 || sp.values.byteOffset < 0) {
            throw Error(s.name + ": sparse byteOffset is negative");
        }
        s.sparseIndices = packedBytes(model, sp.indices.bufferView, size_t(sp.indices.byteOffset),
                                      s.sparseCount, s.sparseIndexSize, s.name + " sparse indices");
        s.sparseValues = packedBytes(model, sp.values.bufferView, size_t(sp.values.byteOffset),
                                     s.sparseCount, s.elemSize, s.name + " sparse values");
    }
    return s;
}

/** Decodes every component through `convert(double)`; sizes were checked by prepare(). */
template <typename T, typename Convert>
std::vector<T> decode(const Source& s, Convert convert) {
    const tinygltf::Accessor& acc = *s.acc;
    const size_t n = size_t(s.components);
    std::vector<T> out(acc.count * n, convert(0.0));
    if (s.dense) {
        for (size_t i = 0; i < acc.count; ++i) {
            for (size_t c = 0; c < n; ++c) {
                out[i * n + c] = convert(readComponent(s.dense + i * s.stride + c * s.compSize,
                                                       acc.componentType, acc.normalized));
            }
        }
    }
    for (size_t k = 0; k < s.sparseCount; ++k) {
        const size_t target =
            readUnsigned(s.sparseIndices + k * s.sparseIndexSize, s.sparseIndexType);
        if (target >= acc.count) {
            throw Error(s.name + ": sparse index " + str(target) + " out of range (count " +
                        str(acc.count) + ")");
        }
        for (size_t c = 0; c < n; ++c) {
            out[target * n + c] =
                convert(readComponent(s.sparseValues + k * s.elemSize + c * s.compSize,
                                      acc.componentType, acc.normalized));
        }
    }
    return out;
}

}  // namespace

std::vector<float> readFloats(const tinygltf::Model& model, int index, int components,
                              const std::string& what, const std::string& attribute,
                              ComponentRule rule) {
    const Source s = prepare(model, index, components, what + " " + attribute);
    const int type = s.acc->componentType;
    const bool normalizedUnsigned =
        s.acc->normalized && (type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                              type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
    if (rule == ComponentRule::Float && type != TINYGLTF_COMPONENT_TYPE_FLOAT) {
        throw Error(s.name + ": componentType " + componentTypeName(type) + " is not allowed; " +
                    attribute + " must be FLOAT " + componentsName(components));
    }
    if (rule == ComponentRule::FloatOrNormalizedUnsigned &&
        !(type == TINYGLTF_COMPONENT_TYPE_FLOAT || normalizedUnsigned)) {
        throw Error(s.name + ": componentType " + componentTypeName(type) +
                    (s.acc->normalized ? " (normalized)" : "") + " is not allowed; " + attribute +
                    " must be FLOAT or normalized UNSIGNED_BYTE / UNSIGNED_SHORT");
    }
    std::vector<float> out = decode<float>(s, [](double v) { return float(v); });
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < out.size(); ++i) {
        if (!std::isfinite(out[i]) && bad++ == 0) first = i / size_t(components);
    }
    if (bad > 0) {
        size_t badElements = 0;
        for (size_t e = 0; e < s.acc->count; ++e) {
            bool finite = true;
            for (size_t c = 0; c < size_t(components); ++c)
                finite &= std::isfinite(out[e * size_t(components) + c]);
            badElements += finite ? 0 : 1;
        }
        throw Error(s.name + ": " + str(badElements) + " of " + str(s.acc->count) + " " +
                    attribute + " values are NaN or infinite (first at element " + str(first) +
                    ")");
    }
    return out;
}

std::vector<uint32_t> readIndices(const tinygltf::Model& model, int index,
                                  const std::string& what) {
    const Source s = prepare(model, index, 1, what + " indices");
    if (!isUnsignedInteger(s.acc->componentType)) {
        throw Error(s.name + ": componentType " + componentTypeName(s.acc->componentType) +
                    " is not allowed; indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or "
                    "UNSIGNED_INT");
    }
    if (s.acc->normalized) throw Error(s.name + ": indices must not be normalized");
    // Unsigned integers of at most 32 bits are exact in a double
    return decode<uint32_t>(s, [](double v) { return uint32_t(v); });
}

}  // namespace gilab::gltf
