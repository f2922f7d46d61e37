#pragma once
/// \file Test helper: a GoogleTest environment that limits TBB to one worker thread for the
/// whole program. For programs of long scene runs whose subject is the physics, not threading:
/// ctest runs two tests at once on the 2-core machines, where two threads each only share the
/// cores and cost more CPU (validate --quick alone, 2026-12-08: 336 s of CPU on 2 threads, 291 s
/// on 1; jet_nozzle, 40 steps: 42.7 s against 37.8 s). Results do not depend on the thread count
/// (Resume.OneAndTwoThreadsWriteTheSameFrames). Register it once per program:
///   ::testing::Environment* const ONE_WORKER_THREAD =
///       ::testing::AddGlobalTestEnvironment(new meniscus::testing::OneWorkerThread);

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <memory>

namespace meniscus::testing {

class OneWorkerThread : public ::testing::Environment {
public:
    void SetUp() override {
        m_limit =
            std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, 1);
    }
    void TearDown() override { m_limit.reset(); }

private:
    std::unique_ptr<tbb::global_control> m_limit;
};

}  // namespace meniscus::testing
