#pragma once
/// \file Checks on JSON text before and after nlohmann::json has parsed it, for what the parser
/// cannot say itself: nesting deep enough to run a recursive parse out of stack, and where a
/// number too large for a double sits (the parser's error gives no position).

#include <string>

namespace meniscus::app {

/// Deepest nesting of arrays and objects in JSON text (brackets outside strings). Checked
/// before parsing, so that no recursion over the document can run out of stack.
int json_nesting_depth(const std::string& text);

/// "/path: expected a number, got 1e400, beyond the range of a double ..." for the first number
/// in `text` that nlohmann::json cannot hold, found by a SAX pass that follows the JSON pointer.
std::string number_overflow_message(const std::string& text);

}  // namespace meniscus::app
