#pragma once
/// \file Exact binary state for checkpoints: BinaryWriter appends values as their bytes,
/// BinaryReader reads them back with every length checked against what is left, so a
/// truncated or corrupt buffer throws FormatError instead of reading past its end or
/// allocating what a bad count asks for. Native byte order: a checkpoint is resumed on the
/// machine (or kind of machine) that wrote it. Header-only.

#include <Eigen/Core>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace meniscus {

/// A state buffer that is truncated, corrupt or inconsistent with what reads it.
class FormatError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// 64-bit FNV-1a of `size` bytes: detects truncation and stray changes of a checkpoint (not
/// meant to resist deliberate tampering).
inline std::uint64_t fnv1a64(const char* data, std::size_t size) {
    std::uint64_t h = 14695981039346656037ull;
    for (std::size_t i = 0; i < size; ++i) {
        h ^= static_cast<unsigned char>(data[i]);
        h *= 1099511628211ull;
    }
    return h;
}

class BinaryWriter {
public:
    template <class T>
    void put(const T& value) {
        static_assert(std::is_trivially_copyable_v<T>, "put: plain values only");
        append(&value, sizeof(T));
    }
    void put(const Eigen::Vector3d& v) { append(v.data(), 3 * sizeof(double)); }
    void put_string(const std::string& s) {
        put<std::uint64_t>(s.size());
        append(s.data(), s.size());
    }
    template <class T>
    void put_vector(const std::vector<T>& v) {
        put<std::uint64_t>(v.size());
        if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
            for (const Eigen::Vector3d& x : v)
                put(x);
        } else {
            static_assert(std::is_trivially_copyable_v<T>, "put_vector: plain values only");
            append(v.data(), v.size() * sizeof(T));
        }
    }
    template <class T>
    void put_nested(const std::vector<std::vector<T>>& v) {
        put<std::uint64_t>(v.size());
        for (const std::vector<T>& inner : v)
            put_vector(inner);
    }

    const std::string& bytes() const { return m_bytes; }
    std::string take() { return std::move(m_bytes); }

private:
    void append(const void* data, std::size_t size) {
        m_bytes.append(static_cast<const char*>(data), size);
    }
    std::string m_bytes;
};

class BinaryReader {
public:
    /// Reads from `size` bytes at `data` (not copied: they must outlive the reader).
    BinaryReader(const char* data, std::size_t size) : m_data(data), m_size(size) {}

    template <class T>
    T get() {
        static_assert(std::is_trivially_copyable_v<T>, "get: plain values only");
        T value;
        copy_out(&value, sizeof(T));
        return value;
    }
    Eigen::Vector3d get_vec3() {
        Eigen::Vector3d v;
        copy_out(v.data(), 3 * sizeof(double));
        return v;
    }
    std::string get_string() {
        const std::size_t n = count(1);
        std::string s(m_data + m_pos, n);
        m_pos += n;
        return s;
    }
    template <class T>
    std::vector<T> get_vector() {
        if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
            const std::size_t n = count(3 * sizeof(double));
            std::vector<Eigen::Vector3d> v(n);
            for (Eigen::Vector3d& x : v)
                x = get_vec3();
            return v;
        } else {
            static_assert(std::is_trivially_copyable_v<T>, "get_vector: plain values only");
            const std::size_t n = count(sizeof(T));
            std::vector<T> v(n);
            copy_out(v.data(), n * sizeof(T));
            return v;
        }
    }
    template <class T>
    std::vector<std::vector<T>> get_nested() {
        // Each inner vector takes at least its 8-byte count.
        const std::size_t n = count(sizeof(std::uint64_t));
        std::vector<std::vector<T>> v(n);
        for (std::vector<T>& inner : v)
            inner = get_vector<T>();
        return v;
    }

    std::size_t remaining() const { return m_size - m_pos; }
    bool at_end() const { return m_pos == m_size; }

private:
    /// Reads an element count and checks that `element_size` bytes per element are left.
    std::size_t count(std::size_t element_size) {
        const std::uint64_t n = get<std::uint64_t>();
        if (n > remaining() / element_size)
            throw FormatError("a count of " + std::to_string(n) + " runs past the end of the data");
        return static_cast<std::size_t>(n);
    }
    void copy_out(void* out, std::size_t size) {
        if (size > remaining())
            throw FormatError("the data ends early");
        if (size == 0)  // an empty vector's data() may be null, and memcpy must not see null
            return;
        std::memcpy(out, m_data + m_pos, size);
        m_pos += size;
    }
    const char* m_data;
    std::size_t m_size;
    std::size_t m_pos = 0;
};

}  // namespace meniscus
