// Speed of the exact predicates and of continuous collision detection.
//
// Each CCD benchmark runs over a fixed pool of queries; "ns/query" is the mean, and the
// counters give the median per-query time (measured one query at a time with steady_clock),
// the fraction of queries answered true, and for near-degenerate pools the fraction that ran
// out of subdivision budget. The orient3d benchmarks compare the filtered predicate with the
// exact path and report the filter's hit rate.

#include "tracker/ccd.h"
#include "tracker/predicates.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <random>
#include <vector>

namespace {

using Eigen::Vector3d;
using meniscus::tracker::CcdOptions;

struct Query {
    std::array<Vector3d, 4> x0;
    std::array<Vector3d, 4> x1;
};

constexpr int POOL_SIZE = 4096;

std::vector<Query> random_pool(std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Query> pool(POOL_SIZE);
    for (Query& q : pool) {
        for (int i = 0; i < 4; ++i) {
            q.x0[i] = Vector3d(u(rng), u(rng), u(rng));
            q.x1[i] = q.x0[i] + 0.5 * Vector3d(u(rng), u(rng), u(rng));
        }
    }
    return pool;
}

/// Near-degenerate: primitives built to touch at a random time (point on the triangle, edges
/// crossing; 1 in 8 edge pairs parallel), then one of them shifted by 2^-k, k in [10, 50], in a
/// random direction; a quarter of the pool is additionally made coplanar (z = 0 for all).
std::vector<Query> near_degenerate_pool(std::uint64_t seed, bool point_triangle) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
    std::normal_distribution<double> g(0.0, 1.0);
    std::vector<Query> pool(POOL_SIZE);
    for (std::size_t n = 0; n < pool.size(); ++n) {
        Query& q = pool[n];
        const bool planar = n % 4 == 0;
        auto rv = [&] { return Vector3d(u(rng), u(rng), planar ? 0.0 : u(rng)); };
        const double t = unit(rng);
        std::array<Vector3d, 4> at;
        if (point_triangle) {
            const Vector3d a = rv(), b = rv(), c = rv();
            double beta = unit(rng), gamma = unit(rng);
            if (beta + gamma > 1.0) {
                beta = 1.0 - beta;
                gamma = 1.0 - gamma;
            }
            at = {(1 - beta - gamma) * a + beta * b + gamma * c, a, b, c};
        } else {
            const Vector3d x = rv(), da = rv();
            const Vector3d db = n % 8 == 1 ? Vector3d(-1.5 * da) : rv();
            const double s = unit(rng), v = unit(rng);
            at = {x - s * da, x + (1 - s) * da, x - v * db, x + (1 - v) * db};
        }
        const double offset = std::ldexp(1.0, -std::uniform_int_distribution<int>(10, 50)(rng));
        Vector3d dir(g(rng), g(rng), planar ? 0.0 : g(rng));
        dir.normalize();
        for (int i = 0; i < 4; ++i) {
            const Vector3d d = rv();
            q.x0[i] = at[i] - t * d;
            q.x1[i] = at[i] + (1 - t) * d;
            const bool moved = point_triangle ? i == 0 : i >= 2;
            if (moved) {
                q.x0[i] += offset * dir;
                q.x1[i] += offset * dir;
            }
        }
    }
    return pool;
}

bool run_pt(const Query& q) {
    return meniscus::tracker::point_triangle_ccd(q.x0[0], q.x0[1], q.x0[2], q.x0[3], q.x1[0],
                                                 q.x1[1], q.x1[2], q.x1[3]);
}

bool run_ee(const Query& q) {
    return meniscus::tracker::edge_edge_ccd(q.x0[0], q.x0[1], q.x0[2], q.x0[3], q.x1[0], q.x1[1],
                                            q.x1[2], q.x1[3]);
}

bool inconclusive(const Query& q, bool point_triangle) {
    const auto r =
        point_triangle
            ? meniscus::tracker::point_triangle_ccd_detailed(q.x0[0], q.x0[1], q.x0[2], q.x0[3],
                                                             q.x1[0], q.x1[1], q.x1[2], q.x1[3])
            : meniscus::tracker::edge_edge_ccd_detailed(q.x0[0], q.x0[1], q.x0[2], q.x0[3], q.x1[0],
                                                        q.x1[1], q.x1[2], q.x1[3]);
    return r.inconclusive;
}

template <typename Run>
void ccd_benchmark(benchmark::State& state, const std::vector<Query>& pool, Run run,
                   bool point_triangle) {
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(run(pool[i]));
        i = (i + 1) % pool.size();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
    // Per-query statistics, measured once outside the timed loop.
    std::vector<double> ns;
    ns.reserve(pool.size());
    int positives = 0;
    int budget = 0;
    for (const Query& q : pool) {
        const auto start = std::chrono::steady_clock::now();
        const bool hit = run(q);
        const auto stop = std::chrono::steady_clock::now();
        ns.push_back(std::chrono::duration<double, std::nano>(stop - start).count());
        positives += hit ? 1 : 0;
        budget += (hit && inconclusive(q, point_triangle)) ? 1 : 0;
    }
    std::nth_element(ns.begin(), ns.begin() + ns.size() / 2, ns.end());
    state.counters["median_ns"] = ns[ns.size() / 2];
    std::nth_element(ns.begin(), ns.begin() + ns.size() * 99 / 100, ns.end());
    state.counters["p99_ns"] = ns[ns.size() * 99 / 100];
    state.counters["true_fraction"] = static_cast<double>(positives) / pool.size();
    state.counters["budget_fraction"] = static_cast<double>(budget) / pool.size();
}

void BM_PointTriangleCcdRandom(benchmark::State& state) {
    static const auto pool = random_pool(1);
    ccd_benchmark(state, pool, run_pt, true);
}
void BM_EdgeEdgeCcdRandom(benchmark::State& state) {
    static const auto pool = random_pool(2);
    ccd_benchmark(state, pool, run_ee, false);
}
void BM_PointTriangleCcdNearDegenerate(benchmark::State& state) {
    static const auto pool = near_degenerate_pool(3, true);
    ccd_benchmark(state, pool, run_pt, true);
}
void BM_EdgeEdgeCcdNearDegenerate(benchmark::State& state) {
    static const auto pool = near_degenerate_pool(4, false);
    ccd_benchmark(state, pool, run_ee, false);
}

BENCHMARK(BM_PointTriangleCcdRandom);
BENCHMARK(BM_EdgeEdgeCcdRandom);
BENCHMARK(BM_PointTriangleCcdNearDegenerate);
BENCHMARK(BM_EdgeEdgeCcdNearDegenerate);

// ---------------------------------------------------------------------------------------------
// orient3d

std::vector<std::array<Vector3d, 4>> orient_pool(std::uint64_t seed, bool nearly_coplanar) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<std::array<Vector3d, 4>> pool(POOL_SIZE);
    for (auto& p : pool) {
        for (int i = 0; i < 4; ++i) {
            p[i] = Vector3d(u(rng), u(rng), u(rng));
        }
        if (nearly_coplanar) {
            // Rounded affine combination: coplanar up to a few ulps, often exactly.
            p[3] = p[0] + u(rng) * (p[1] - p[0]) + u(rng) * (p[2] - p[0]);
        }
    }
    return pool;
}

template <typename Predicate>
void orient_benchmark(benchmark::State& state, const std::vector<std::array<Vector3d, 4>>& pool,
                      Predicate predicate) {
    std::size_t i = 0;
    for (auto _ : state) {
        const auto& p = pool[i];
        benchmark::DoNotOptimize(predicate(p[0], p[1], p[2], p[3]));
        i = (i + 1) % pool.size();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
    int hits = 0;
    for (const auto& p : pool) {
        hits += meniscus::tracker::orient3d_filtered(p[0], p[1], p[2], p[3]) !=
                        meniscus::tracker::SIGN_UNCERTAIN
                    ? 1
                    : 0;
    }
    state.counters["filter_hit_rate"] = static_cast<double>(hits) / pool.size();
}

void BM_Orient3dRandom(benchmark::State& state) {
    static const auto pool = orient_pool(5, false);
    orient_benchmark(state, pool, meniscus::tracker::orient3d);
}
void BM_Orient3dExactPathRandom(benchmark::State& state) {
    static const auto pool = orient_pool(5, false);
    orient_benchmark(state, pool, meniscus::tracker::orient3d_exact);
}
void BM_Orient3dNearlyCoplanar(benchmark::State& state) {
    static const auto pool = orient_pool(6, true);
    orient_benchmark(state, pool, meniscus::tracker::orient3d);
}
void BM_Orient3dExactPathNearlyCoplanar(benchmark::State& state) {
    static const auto pool = orient_pool(6, true);
    orient_benchmark(state, pool, meniscus::tracker::orient3d_exact);
}

BENCHMARK(BM_Orient3dRandom);
BENCHMARK(BM_Orient3dExactPathRandom);
BENCHMARK(BM_Orient3dNearlyCoplanar);
BENCHMARK(BM_Orient3dExactPathNearlyCoplanar);

}  // namespace

BENCHMARK_MAIN();
