#pragma once
/// \file Dense 3D array with contiguous storage, the storage of every grid field in fluid/.
///
/// Layout: element (i, j, k) lives at flat index i + ni·(j + nj·k), so i varies fastest. There are
/// no per-element virtual calls and no bounds checks in Release (MENISCUS_ASSERT when enabled).

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

#include "common/assert.h"
#include "common/binary_io.h"

namespace meniscus::fluid {

/// Dense ni × nj × nk array of T, i fastest (see file comment).
template <class T>
class Array3 {
public:
    Array3() = default;
    /// Creates an ni × nj × nk array filled with `value`. Sizes must be ≥ 0.
    Array3(int ni, int nj, int nk, T value = T()) { resize(ni, nj, nk, value); }

    /// Resizes to ni × nj × nk and fills every element with `value`.
    void resize(int ni, int nj, int nk, T value = T()) {
        MENISCUS_ASSERT(ni >= 0 && nj >= 0 && nk >= 0, "Array3 sizes must be non-negative");
        m_ni = ni;
        m_nj = nj;
        m_nk = nk;
        m_data.assign(static_cast<std::size_t>(ni) * nj * nk, value);
    }

    /// Extent along i (fastest), j and k.
    int ni() const { return m_ni; }
    int nj() const { return m_nj; }
    int nk() const { return m_nk; }
    /// Number of elements ni·nj·nk.
    std::size_t size() const { return m_data.size(); }

    /// Flat index of (i, j, k): i + ni·(j + nj·k).
    std::size_t index(int i, int j, int k) const {
        return static_cast<std::size_t>(i) +
               static_cast<std::size_t>(m_ni) *
                   (static_cast<std::size_t>(j) + static_cast<std::size_t>(m_nj) * k);
    }

    /// The flat-index step along axis 0 (i), 1 (j) or 2 (k): 1, ni or ni·nj.
    std::size_t stride(int axis) const {
        return axis == 0 ? 1
                         : static_cast<std::size_t>(m_ni) *
                               (axis == 1 ? 1 : static_cast<std::size_t>(m_nj));
    }

    /// True when (i, j, k) is a valid element.
    bool contains(int i, int j, int k) const {
        return i >= 0 && j >= 0 && k >= 0 && i < m_ni && j < m_nj && k < m_nk;
    }

    /// Element (i, j, k); bounds-checked by MENISCUS_ASSERT when asserts are on (use flat
    /// indices in hot loops).
    T& operator()(int i, int j, int k) {
        MENISCUS_ASSERT(contains(i, j, k), "Array3 index out of range");
        return m_data[index(i, j, k)];
    }
    const T& operator()(int i, int j, int k) const {
        MENISCUS_ASSERT(contains(i, j, k), "Array3 index out of range");
        return m_data[index(i, j, k)];
    }

    /// Element at flat index i + ni·(j + nj·k), unchecked.
    T& operator[](std::size_t flat) { return m_data[flat]; }
    const T& operator[](std::size_t flat) const { return m_data[flat]; }

    /// Sets every element to `value`.
    void fill(T value) { std::fill(m_data.begin(), m_data.end(), value); }

    /// Contiguous storage in flat-index order.
    T* data() { return m_data.data(); }
    const T* data() const { return m_data.data(); }
    std::vector<T>& storage() { return m_data; }
    const std::vector<T>& storage() const { return m_data; }

private:
    int m_ni = 0;
    int m_nj = 0;
    int m_nk = 0;
    std::vector<T> m_data;
};

/// Writes the array's extents and values (checkpoints).
template <class T>
void save_array(BinaryWriter& out, const Array3<T>& a) {
    out.put(a.ni());
    out.put(a.nj());
    out.put(a.nk());
    out.put_vector(a.storage());
}

/// Reads what save_array() wrote into `a`, whose extents it must have (the reader's grid is
/// built from the same scene); throws FormatError naming `what` otherwise or if data is missing.
template <class T>
void load_array(BinaryReader& in, Array3<T>& a, const char* what) {
    const int ni = in.get<int>(), nj = in.get<int>(), nk = in.get<int>();
    std::vector<T> values = in.get_vector<T>();
    if (ni != a.ni() || nj != a.nj() || nk != a.nk() ||
        values.size() != static_cast<std::size_t>(a.size()))
        throw FormatError(std::string(what) + ": the saved array is " + std::to_string(ni) + " x " +
                          std::to_string(nj) + " x " + std::to_string(nk) + ", the grid's " +
                          std::to_string(a.ni()) + " x " + std::to_string(a.nj()) + " x " +
                          std::to_string(a.nk()));
    a.storage() = std::move(values);
}

}  // namespace meniscus::fluid
