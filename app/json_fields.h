#pragma once
/// \file One list of fields per options struct drives both scene parsing and the generated key
/// reference. Each section is a template `visit_fields(Visitor&, Options&)` calling
/// `v.number(...)`, `v.integer(...)`, ... The JsonReader visitor fills the struct from JSON,
/// rejecting unknown keys, wrong types and out-of-range values with the JSON path; the
/// ReferenceWriter visitor lists key, type, default (the struct's own), unit and meaning.

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <array>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace meniscus::app {

/// A scene file error: the message starts with the JSON path, e.g.
/// "/tracker/remesh/max_edge_fraction: expected a number > 0".
class SceneError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Allowed range of a number: [min, max] with optional exclusive ends.
struct Range {
    double min = -std::numeric_limits<double>::infinity();
    double max = std::numeric_limits<double>::infinity();
    bool min_exclusive = false;
    bool max_exclusive = false;
    static Range positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
    static Range non_negative() { return {0.0, std::numeric_limits<double>::infinity()}; }
    static Range at_least(double m) { return {m, std::numeric_limits<double>::infinity()}; }
    static Range between(double a, double b) { return {a, b}; }
    static Range any() { return {}; }
    bool contains(double v) const;
    std::string describe() const;  ///< "> 0", ">= 1", "in [0, 1]", "" for any
};

/// Reads one JSON object into fields, tracking the path for errors.
class JsonReader {
public:
    /// `object` must be a JSON object (else SceneError "<path>: expected an object").
    JsonReader(const nlohmann::json& object, std::string path);

    void number(const char* key, double& value, Range range, const char* unit, const char* meaning);
    void integer(const char* key, int& value, Range range, const char* unit, const char* meaning);
    void boolean(const char* key, bool& value, const char* meaning);
    void text(const char* key, std::string& value, const char* meaning);
    void choice(const char* key, std::string& value, const std::vector<std::string>& allowed,
                const char* meaning);
    void vec3(const char* key, Eigen::Vector3d& value, Range range, const char* unit,
              const char* meaning);
    /// An array of 3 texts; a number stands for its own text (e.g. the expressions of
    /// /flow/expression/velocity, where 0 means "0").
    void text3(const char* key, std::array<std::string, 3>& value, const char* meaning);
    /// An object of named numbers, e.g. {"omega": 6.28}; replaces `value`.
    void number_map(const char* key, std::map<std::string, double>& value, const char* unit,
                    const char* meaning);
    /// Visits a nested section with `visit(JsonReader&)` if the key is present.
    template <typename Visit>
    void section(const char* key, const char* meaning, Visit&& visit) {
        m_known.insert(key);
        if (!m_object.contains(key))
            return;
        JsonReader child(m_object.at(key), m_path + "/" + key);
        visit(child);
        child.finish();
    }
    /// Marks a key as handled elsewhere (e.g. a polymorphic shape tree).
    void known(const char* key) { m_known.insert(key); }
    bool has(const char* key) const { return m_object.contains(key); }
    const nlohmann::json& raw(const char* key) const { return m_object.at(key); }
    const std::string& path() const { return m_path; }
    /// Throws SceneError for the first key that no field claimed.
    void finish() const;
    [[noreturn]] void fail(const std::string& key, const std::string& what) const;

private:
    const nlohmann::json* lookup(const char* key);
    const nlohmann::json& m_object;
    std::string m_path;
    std::set<std::string> m_known;
};

/// Collects, for the generated reference, one Markdown table of fields per section: key, type,
/// default (read from a default-constructed options struct), unit and meaning.
class ReferenceWriter {
public:
    struct Row {
        std::string key, type, default_value, unit, meaning;
    };
    struct Table {
        std::string path, meaning;
        std::vector<Row> rows;
    };
    /// Starts a reference whose top-level table has the given path ("" = scene root).
    ReferenceWriter(std::vector<Table>& tables, std::string path, std::string meaning);

    void number(const char* key, double& value, Range range, const char* unit, const char* meaning);
    void integer(const char* key, int& value, Range range, const char* unit, const char* meaning);
    void boolean(const char* key, bool& value, const char* meaning);
    void text(const char* key, std::string& value, const char* meaning);
    void choice(const char* key, std::string& value, const std::vector<std::string>& allowed,
                const char* meaning);
    void vec3(const char* key, Eigen::Vector3d& value, Range range, const char* unit,
              const char* meaning);
    void text3(const char* key, std::array<std::string, 3>& value, const char* meaning);
    void number_map(const char* key, std::map<std::string, double>& value, const char* unit,
                    const char* meaning);
    template <typename Visit>
    void section(const char* key, const char* meaning, Visit&& visit) {
        add({key, "object", "", "", std::string(meaning) + " (see " + m_path + "/" + key + ")"});
        ReferenceWriter child(m_tables, m_path + "/" + key, meaning);
        visit(child);
    }
    void known(const char*) {}
    /// Adds a row by hand (for fields that are not plain values, like shape trees).
    void add(Row row);
    /// Renders every table as Markdown.
    static std::string markdown(const std::vector<Table>& tables);

private:
    std::vector<Table>& m_tables;
    size_t m_index;
    std::string m_path;
};

}  // namespace meniscus::app
