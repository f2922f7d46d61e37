#include "app/json_fields.h"

#include <cmath>
#include <cstdint>
#include <iomanip>

namespace meniscus::app {

namespace {

std::string format_number(double v) {
    std::ostringstream s;
    s << std::setprecision(10) << v;
    return s.str();
}

std::string type_name(const nlohmann::json& j) {
    if (j.is_null())
        return "null";
    if (j.is_boolean())
        return "a boolean";
    if (j.is_number())
        return "a number";
    if (j.is_string())
        return "a string";
    if (j.is_array())
        return "an array";
    return "an object";
}

/// Magnitudes a scene number may have (0 aside): Meniscus computes in SI units with doubles, and
/// products of a few numbers beyond these overflow or underflow (1e308 m/s, a density of
/// 1e-300); no physical scene needs them.
constexpr double MAX_MAGNITUDE = 1e30;
constexpr double MIN_MAGNITUDE = 1e-30;

bool magnitude_supported(double v) {
    const double a = std::abs(v);
    return a == 0.0 || (a >= MIN_MAGNITUDE && a <= MAX_MAGNITUDE);
}

const char* MAGNITUDE_RULE = " (magnitudes outside [1e-30, 1e30] are not supported)";

}  // namespace

bool Range::contains(double v) const {
    if (!std::isfinite(v))
        return false;
    if (min_exclusive ? !(v > min) : !(v >= min))
        return false;
    if (max_exclusive ? !(v < max) : !(v <= max))
        return false;
    return true;
}

std::string Range::describe() const {
    const bool has_min = std::isfinite(min), has_max = std::isfinite(max);
    if (has_min && has_max)
        return std::string("in ") + (min_exclusive ? "(" : "[") + format_number(min) + ", " +
               format_number(max) + (max_exclusive ? ")" : "]");
    if (has_min)
        return std::string(min_exclusive ? "> " : ">= ") + format_number(min);
    if (has_max)
        return std::string(max_exclusive ? "< " : "<= ") + format_number(max);
    return "";
}

JsonReader::JsonReader(const nlohmann::json& object, std::string path)
    : m_object(object), m_path(std::move(path)) {
    if (!m_object.is_object())
        throw SceneError((m_path.empty() ? "/" : m_path) + ": expected an object, got " +
                         type_name(m_object));
}

void JsonReader::fail(const std::string& key, const std::string& what) const {
    throw SceneError(m_path + "/" + key + ": " + what);
}

const nlohmann::json* JsonReader::lookup(const char* key) {
    m_known.insert(key);
    auto it = m_object.find(key);
    return it == m_object.end() ? nullptr : &*it;
}

void JsonReader::number(const char* key, double& value, Range range, const char*, const char*) {
    const nlohmann::json* j = lookup(key);
    if (!j)
        return;
    const std::string expected =
        "expected a number" + (range.describe().empty() ? "" : " " + range.describe());
    if (!j->is_number())
        fail(key, expected + ", got " + type_name(*j));
    const double v = j->get<double>();
    if (!range.contains(v))
        fail(key, expected + ", got " + format_number(v));
    if (!magnitude_supported(v))
        fail(key, expected + ", got " + format_number(v) + MAGNITUDE_RULE);
    value = v;
}

void JsonReader::integer(const char* key, int& value, Range range, const char*, const char*) {
    const nlohmann::json* j = lookup(key);
    if (!j)
        return;
    const std::string expected =
        "expected an integer" + (range.describe().empty() ? "" : " " + range.describe());
    if (!j->is_number_integer())
        fail(key, expected + ", got " + (j->is_number() ? format_number(j->get<double>()) : type_name(*j)));
    if (j->is_number_unsigned() &&
        j->get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
        fail(key, expected + ", got " + std::to_string(j->get<std::uint64_t>()));
    const long long v = j->get<long long>();
    if (!range.contains(static_cast<double>(v)) || v > std::numeric_limits<int>::max() ||
        v < std::numeric_limits<int>::min())
        fail(key, expected + ", got " + std::to_string(v));
    value = static_cast<int>(v);
}

void JsonReader::boolean(const char* key, bool& value, const char*) {
    const nlohmann::json* j = lookup(key);
    if (!j)
        return;
    if (!j->is_boolean())
        fail(key, "expected true or false, got " + type_name(*j));
    value = j->get<bool>();
}

void JsonReader::text(const char* key, std::string& value, const char*) {
    const nlohmann::json* j = lookup(key);
    if (!j)
        return;
    if (!j->is_string())
        fail(key, "expected a string, got " + type_name(*j));
    value = j->get<std::string>();
}

void JsonReader::choice(const char* key, std::string& value,
                        const std::vector<std::string>& allowed, const char*) {
    const nlohmann::json* j = lookup(key);
    if (!j)
        return;
    std::string list;
    for (const auto& a : allowed)
        list += (list.empty() ? "" : ", ") + ("\"" + a + "\"");
    if (!j->is_string())
        fail(key, "expected one of " + list + ", got " + type_name(*j));
    const std::string v = j->get<std::string>();
    for (const auto& a : allowed)
        if (a == v) {
            value = v;
            return;
        }
    fail(key, "expected one of " + list + ", got \"" + v + "\"");
}

void JsonReader::vec3(const char* key, Eigen::Vector3d& value, Range range, const char*,
                      const char*) {
    const nlohmann::json* j = lookup(key);
    if (!j)
        return;
    const std::string expected =
        "expected an array of 3 numbers" + (range.describe().empty() ? "" : " " + range.describe());
    if (!j->is_array())
        fail(key, expected + ", got " + type_name(*j));
    if (j->size() != 3)
        fail(key, expected + ", got an array of " + std::to_string(j->size()));
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) {
        const auto& c = (*j)[static_cast<size_t>(i)];
        const std::string component = std::string(key) + "/" + std::to_string(i);
        const std::string expected_component =
            "expected a number" + (range.describe().empty() ? "" : " " + range.describe());
        if (!c.is_number())
            fail(component, expected_component + ", got " + type_name(c));
        if (!range.contains(c.get<double>()))
            fail(component, expected_component + ", got " + format_number(c.get<double>()));
        if (!magnitude_supported(c.get<double>()))
            fail(component, expected_component + ", got " + format_number(c.get<double>()) +
                                MAGNITUDE_RULE);
        v[i] = c.get<double>();
    }
    value = v;
}

void JsonReader::text3(const char* key, std::array<std::string, 3>& value, const char*) {
    const nlohmann::json* j = lookup(key);
    if (!j)
        return;
    const std::string expected = "expected an array of 3 strings (or numbers)";
    if (!j->is_array() || j->size() != 3)
        fail(key, expected + ", got " + type_name(*j) +
                      (j->is_array() ? " of " + std::to_string(j->size()) : ""));
    std::array<std::string, 3> v;
    for (size_t i = 0; i < 3; ++i) {
        const auto& c = (*j)[i];
        if (c.is_string())
            v[i] = c.get<std::string>();
        else if (c.is_number())
            v[i] = c.dump();  // nlohmann writes doubles so that they read back exactly
        else
            fail(std::string(key) + "/" + std::to_string(i),
                 "expected a string or a number, got " + type_name(c));
    }
    value = v;
}

void JsonReader::number_map(const char* key, std::map<std::string, double>& value, const char*,
                            const char*) {
    const nlohmann::json* j = lookup(key);
    if (!j)
        return;
    if (!j->is_object())
        fail(key, "expected an object of named numbers, got " + type_name(*j));
    std::map<std::string, double> v;
    for (auto it = j->begin(); it != j->end(); ++it) {
        if (!it->is_number() || !std::isfinite(it->get<double>()))
            fail(std::string(key) + "/" + it.key(), "expected a number, got " + type_name(*it));
        v[it.key()] = it->get<double>();
    }
    value = v;
}

void JsonReader::finish() const {
    for (auto it = m_object.begin(); it != m_object.end(); ++it) {
        if (m_known.count(it.key()) == 0) {
            std::string list;
            for (const auto& k : m_known)
                list += (list.empty() ? "" : ", ") + k;
            fail(it.key(), "unknown key (known keys here: " + list + ")");
        }
    }
}

ReferenceWriter::ReferenceWriter(std::vector<Table>& tables, std::string path, std::string meaning)
    : m_tables(tables), m_index(tables.size()), m_path(std::move(path)) {
    m_tables.push_back({m_path.empty() ? "/" : m_path, std::move(meaning), {}});
}

void ReferenceWriter::add(Row row) {
    m_tables[m_index].rows.push_back(std::move(row));
}

void ReferenceWriter::number(const char* key, double& value, Range range, const char* unit,
                             const char* meaning) {
    add({key, "number " + range.describe(), format_number(value), unit, meaning});
}
void ReferenceWriter::integer(const char* key, int& value, Range range, const char* unit,
                              const char* meaning) {
    add({key, "integer " + range.describe(), std::to_string(value), unit, meaning});
}
void ReferenceWriter::boolean(const char* key, bool& value, const char* meaning) {
    add({key, "boolean", value ? "true" : "false", "", meaning});
}
void ReferenceWriter::text(const char* key, std::string& value, const char* meaning) {
    add({key, "string", value.empty() ? "\"\"" : "\"" + value + "\"", "", meaning});
}
void ReferenceWriter::choice(const char* key, std::string& value,
                             const std::vector<std::string>& allowed, const char* meaning) {
    std::string list;
    for (const auto& a : allowed)
        list += (list.empty() ? "" : " \\| ") + ("`" + a + "`");
    add({key, "one of " + list, "\"" + value + "\"", "", meaning});
}
void ReferenceWriter::vec3(const char* key, Eigen::Vector3d& value, Range range, const char* unit,
                           const char* meaning) {
    add({key, "3 numbers " + range.describe(),
         "[" + format_number(value.x()) + ", " + format_number(value.y()) + ", " +
             format_number(value.z()) + "]",
         unit, meaning});
}

void ReferenceWriter::text3(const char* key, std::array<std::string, 3>& value,
                            const char* meaning) {
    add({key, "3 strings", "[\"" + value[0] + "\", \"" + value[1] + "\", \"" + value[2] + "\"]", "",
         meaning});
}
void ReferenceWriter::number_map(const char* key, std::map<std::string, double>& value,
                                 const char* unit, const char* meaning) {
    std::string text;
    for (const auto& [name, v] : value)
        text += (text.empty() ? "" : ", ") + ("\"" + name + "\": " + format_number(v));
    add({key, "object of numbers", "{" + text + "}", unit, meaning});
}

std::string ReferenceWriter::markdown(const std::vector<Table>& tables) {
    std::ostringstream out;
    for (const Table& t : tables) {
        out << "### `" << t.path << "`\n\n";
        if (!t.meaning.empty())
            out << t.meaning << "\n\n";
        out << "| key | type | default | unit | meaning |\n|---|---|---|---|---|\n";
        for (const Row& r : t.rows)
            out << "| `" << r.key << "` | " << r.type << " | " << r.default_value << " | " << r.unit
                << " | " << r.meaning << " |\n";
        out << "\n";
    }
    return out.str();
}

}  // namespace meniscus::app
