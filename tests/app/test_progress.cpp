// Progress lines off a terminal: throttled to one per interval, the last always written.
#include "app/progress.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace {

using meniscus::app::format_duration;
using meniscus::app::Progress;

/// Everything written to a temporary (non-terminal) file by `write`.
template <class F>
std::string captured(F&& write) {
    std::FILE* f = std::tmpfile();
    EXPECT_NE(f, nullptr);
    write(f);
    std::rewind(f);
    std::string text;
    char buf[512];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0)
        text.append(buf, n);
    std::fclose(f);
    return text;
}

int count_lines(const std::string& s) {
    int n = 0;
    for (char c : s)
        n += c == '\n' ? 1 : 0;
    return n;
}

TEST(Progress, PlainLinesAreThrottledButTheLastIsAlwaysWritten) {
    const std::string text = captured([](std::FILE* f) {
        Progress p(f, false, "percent", 3600.0);
        for (int k = 1; k <= 100; ++k)
            p.frame_done(k, 100, 0.1 * k, "detail");
        p.finish();
    });
    EXPECT_EQ(count_lines(text), 2) << text;
    EXPECT_EQ(text.rfind("percent 1/100", 0), 0u) << text;
    EXPECT_NE(text.find("percent 100/100 t=10 s"), std::string::npos) << text;
}

TEST(Progress, WithoutAnIntervalEveryFrameGetsALine) {
    const std::string text = captured([](std::FILE* f) {
        Progress p(f, false);
        for (int k = 1; k <= 5; ++k)
            p.frame_done(k, 5, k, "");
    });
    EXPECT_EQ(count_lines(text), 5) << text;
    EXPECT_NE(text.find("frame 3/5"), std::string::npos) << text;
}

TEST(Progress, QuietWritesNothing) {
    const std::string text = captured([](std::FILE* f) {
        Progress p(f, true);
        p.frame_done(1, 1, 1.0, "x");
        p.finish();
    });
    EXPECT_TRUE(text.empty()) << text;
}

TEST(Progress, DurationsReadAsClockTimes) {
    EXPECT_EQ(format_duration(75.0), "01:15");
    EXPECT_EQ(format_duration(3725.0), "1:02:05");
    EXPECT_EQ(format_duration(-1.0), "--:--");
}

}  // namespace
