// The translation unit that builds the test programs' shared precompiled header
// (tests/CMakeLists.txt, meniscus_test_pch); it has no code and no tests of its own.
