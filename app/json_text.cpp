#include "app/json_text.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <vector>

namespace meniscus::app {

namespace {

/// Finds where JSON text holds a number beyond the range of a double (1e400), which
/// nlohmann::json::parse reports without a position: a SAX pass that follows the JSON pointer.
class NumberOverflowLocator final : public nlohmann::json_sax<nlohmann::json> {
public:
    /// The JSON pointer of the value being parsed when the parse failed ("" before any).
    std::string failed_path;
    std::string failed_token;

    bool null() override { return value(); }
    bool boolean(bool) override { return value(); }
    bool number_integer(number_integer_t) override { return value(); }
    bool number_unsigned(number_unsigned_t) override { return value(); }
    bool number_float(number_float_t, const string_t&) override { return value(); }
    bool string(string_t&) override { return value(); }
    bool binary(binary_t&) override { return value(); }
    bool start_object(std::size_t) override { return open(false); }
    bool start_array(std::size_t) override { return open(true); }
    bool end_object() override { return close(); }
    bool end_array() override { return close(); }
    bool key(string_t& k) override {
        std::string escaped;
        for (const char c : k)
            escaped += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
        m_stack.back().segment = escaped;
        return true;
    }
    bool parse_error(std::size_t, const std::string& last_token,
                     const nlohmann::detail::exception&) override {
        failed_token = last_token;
        for (size_t i = 0; i < m_stack.size(); ++i) {
            const Level& l = m_stack[i];
            // The innermost array has not counted the element that failed.
            const bool innermost = i + 1 == m_stack.size();
            failed_path += "/" + (l.array && innermost ? std::to_string(l.count) : l.segment);
        }
        return false;
    }

private:
    struct Level {
        bool array = false;
        long long count = 0;  ///< arrays: elements begun so far
        std::string segment;  ///< the key or index of the value begun last
    };
    bool value() {
        if (!m_stack.empty() && m_stack.back().array)
            m_stack.back().segment = std::to_string(m_stack.back().count++);
        return true;
    }
    bool open(bool array) {
        value();
        m_stack.push_back(Level{array, 0, ""});
        return true;
    }
    bool close() {
        m_stack.pop_back();
        return true;
    }
    std::vector<Level> m_stack;
};

}  // namespace

/// Deepest nesting of arrays and objects in JSON text (brackets outside strings). Checked
/// before parsing, so that no recursion over the document can run out of stack.
int json_nesting_depth(const std::string& text) {
    int depth = 0, deepest = 0;
    bool in_string = false, escaped = false;
    for (const char c : text) {
        if (in_string) {
            if (escaped)
                escaped = false;
            else if (c == '\\')
                escaped = true;
            else if (c == '"')
                in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            deepest = std::max(deepest, ++depth);
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return deepest;
}

/// "/path: the number 1e400 is beyond ..." for a number nlohmann::json cannot hold.
std::string number_overflow_message(const std::string& text) {
    NumberOverflowLocator locator;
    nlohmann::json::sax_parse(text, &locator);
    const std::string where = locator.failed_path.empty() ? "(top level)" : locator.failed_path;
    return where + ": expected a number, got " + locator.failed_token +
           ", beyond the range of a double (magnitudes outside [1e-30, 1e30] are not supported)";
}

}  // namespace meniscus::app
