#pragma once
/// \file The two failures `meniscus` tells apart from a scene error (SceneError, scene.h) and a
/// failed write (WriteError): bad input outside the scene JSON, and a fault of Meniscus itself.

#include <stdexcept>

namespace meniscus::app {

/// Bad user input outside the scene JSON itself (e.g. a broken mesh file): exit code 2.
class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A fault inside Meniscus (not the input's): exit code 1. The message says where it happened
/// (the step and frame) and what failed.
class InternalFailure : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace meniscus::app
