#pragma once
/// \file A parallel filter whose output is the serial loop's, whatever the thread count.

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace meniscus::tracker {

/// Items per task of ordered_parallel_collect().
constexpr std::size_t COLLECT_CHUNK = 4096;

/// What `visit(i, out)` appends for i = 0 … n − 1, in the order of i, computed in parallel
/// chunks: the result is the serial loop's, whatever the thread count.
template <typename T, typename Visit>
std::vector<T> ordered_parallel_collect(std::size_t n, const Visit& visit) {
    const std::size_t chunks = (n + COLLECT_CHUNK - 1) / COLLECT_CHUNK;
    std::vector<std::vector<T>> parts(chunks);
    tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t k) {
        const std::size_t end = std::min(n, (k + 1) * COLLECT_CHUNK);
        for (std::size_t i = k * COLLECT_CHUNK; i < end; ++i)
            visit(i, parts[k]);
    });
    std::size_t total = 0;
    for (const std::vector<T>& part : parts)
        total += part.size();
    std::vector<T> out;
    out.reserve(total);
    for (const std::vector<T>& part : parts)
        out.insert(out.end(), part.begin(), part.end());
    return out;
}

}  // namespace meniscus::tracker
