#pragma once
/// \file The output folder of `meniscus run`, checked before any work starts.

#include <string>

namespace meniscus::app {

/// Creates `dir` if needed and checks that files can be created in it; throws InputError
/// ("--out DIR: ...", exit 2) when it is a file, cannot be created or is not writable. Removes
/// the `*.partial` files an earlier run left when it was killed while writing.
void prepare_output_dir(const std::string& dir);

}  // namespace meniscus::app
