#include "tracker/mesh_io.h"

#include "common/atomic_file.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace meniscus::tracker {

namespace {

/// Digits that make a double round-trip exactly through text.
constexpr int ROUND_TRIP_DIGITS = 17;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
    throw std::runtime_error(path + ": " + what);
}

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

bool host_is_little_endian() {
    const std::uint16_t one = 1;
    unsigned char first = 0;
    std::memcpy(&first, &one, 1);
    return first == 1;
}

/// Live vertices and triangles renumbered densely.
struct DenseMesh {
    std::vector<int> vertices;  // live vertex indices in order
    std::vector<Triangle> triangles;
};

DenseMesh dense(const SurfaceMesh& mesh) {
    DenseMesh d;
    std::vector<int> map(static_cast<size_t>(mesh.num_vertices()), INVALID_INDEX);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        map[static_cast<size_t>(vi)] = static_cast<int>(d.vertices.size());
        d.vertices.push_back(vi);
    }
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        d.triangles.push_back({map[static_cast<size_t>(t[0])], map[static_cast<size_t>(t[1])],
                               map[static_cast<size_t>(t[2])]});
    }
    return d;
}

template <typename T>
void put_le(std::ostream& out, T value) {
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    if (!host_is_little_endian())
        std::reverse(bytes, bytes + sizeof(T));
    out.write(reinterpret_cast<const char*>(bytes), sizeof(T));
}

// ---- PLY reading ------------------------------------------------------------------------

enum class PlyFormat { Ascii, BinaryLittle, BinaryBig };

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

PlyType parse_ply_type(const std::string& name, const std::string& path) {
    if (name == "char" || name == "int8")
        return PlyType::Int8;
    if (name == "uchar" || name == "uint8")
        return PlyType::UInt8;
    if (name == "short" || name == "int16")
        return PlyType::Int16;
    if (name == "ushort" || name == "uint16")
        return PlyType::UInt16;
    if (name == "int" || name == "int32")
        return PlyType::Int32;
    if (name == "uint" || name == "uint32")
        return PlyType::UInt32;
    if (name == "float" || name == "float32")
        return PlyType::Float32;
    if (name == "double" || name == "float64")
        return PlyType::Float64;
    fail(path, "unknown PLY property type '" + name + "'");
}

struct PlyProperty {
    std::string name;
    PlyType type = PlyType::Float32;
    bool is_list = false;
    PlyType count_type = PlyType::UInt8;
};

struct PlyElement {
    std::string name;
    long long count = 0;
    std::vector<PlyProperty> properties;
};

class PlyValueReader {
public:
    PlyValueReader(std::istream& in, PlyFormat format, const std::string& path)
        : m_in(in), m_format(format), m_path(path) {}

    double read(PlyType type) {
        if (m_format == PlyFormat::Ascii) {
            double v = 0.0;
            if (!(m_in >> v))
                fail(m_path, "truncated or malformed ASCII PLY data");
            return v;
        }
        switch (type) {
            case PlyType::Int8:
                return binary<std::int8_t>();
            case PlyType::UInt8:
                return binary<std::uint8_t>();
            case PlyType::Int16:
                return binary<std::int16_t>();
            case PlyType::UInt16:
                return binary<std::uint16_t>();
            case PlyType::Int32:
                return binary<std::int32_t>();
            case PlyType::UInt32:
                return binary<std::uint32_t>();
            case PlyType::Float32:
                return binary<float>();
            case PlyType::Float64:
                return binary<double>();
        }
        return 0.0;
    }

private:
    template <typename T>
    double binary() {
        unsigned char bytes[sizeof(T)];
        if (!m_in.read(reinterpret_cast<char*>(bytes), sizeof(T)))
            fail(m_path, "truncated binary PLY data");
        const bool file_little = m_format == PlyFormat::BinaryLittle;
        if (file_little != host_is_little_endian())
            std::reverse(bytes, bytes + sizeof(T));
        T v;
        std::memcpy(&v, bytes, sizeof(T));
        return static_cast<double>(v);
    }
    std::istream& m_in;
    PlyFormat m_format;
    const std::string& m_path;
};

int property_index(const PlyElement& e, const std::string& name) {
    for (size_t i = 0; i < e.properties.size(); ++i)
        if (e.properties[i].name == name)
            return static_cast<int>(i);
    return -1;
}

/// `index_base`: 1 for OBJ (messages show the file's own numbers), 0 for PLY.
void add_polygon(MeshData& data, const std::vector<long long>& poly, const std::string& path,
                 const std::string& where, int index_base) {
    if (poly.size() < 3)
        fail(path,
             where + ": a face needs at least 3 vertices, got " + std::to_string(poly.size()));
    for (long long v : poly)
        if (v < 0 || v > std::numeric_limits<int>::max())
            fail(path, where + ": vertex index " + std::to_string(v + index_base) +
                           " is out of range");
    const int face = data.triangle_face.empty() ? 0 : data.triangle_face.back() + 1;
    for (size_t k = 1; k + 1 < poly.size(); ++k) {
        data.triangles.push_back(
            {static_cast<int>(poly[0]), static_cast<int>(poly[k]), static_cast<int>(poly[k + 1])});
        data.triangle_face.push_back(face);
    }
}

/// Bytes one value of `type` takes at least in the file (ASCII: a digit and a separator).
double min_value_bytes(PlyType type, PlyFormat format) {
    if (format == PlyFormat::Ascii)
        return 2.0;
    switch (type) {
        case PlyType::Int8:
        case PlyType::UInt8:
            return 1.0;
        case PlyType::Int16:
        case PlyType::UInt16:
            return 2.0;
        case PlyType::Int32:
        case PlyType::UInt32:
        case PlyType::Float32:
            return 4.0;
        case PlyType::Float64:
            return 8.0;
    }
    return 1.0;
}

/// Smallest number of bytes one element can take (a face list has at least 3 entries).
double min_element_bytes(const PlyElement& e, PlyFormat format) {
    double bytes = 0.0;
    for (const PlyProperty& p : e.properties) {
        if (p.is_list) {
            bytes += min_value_bytes(p.count_type, format);
            if (e.name == "face")
                bytes += 3.0 * min_value_bytes(p.type, format);
        } else {
            bytes += min_value_bytes(p.type, format);
        }
    }
    return bytes;
}

}  // namespace

void write_ply(const std::string& path, const SurfaceMesh& mesh,
               const std::vector<Vec3>* velocities) {
    if (velocities && velocities->size() != static_cast<size_t>(mesh.num_vertices()))
        throw std::invalid_argument("write_ply: " + std::to_string(velocities->size()) +
                                    " velocities for " + std::to_string(mesh.num_vertices()) +
                                    " vertex slots");
    const DenseMesh d = dense(mesh);
    std::ofstream out = open_temporary(path, std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\ncomment written by meniscus\n"
        << "element vertex " << d.vertices.size() << "\n"
        << "property double x\nproperty double y\nproperty double z\n";
    if (velocities)
        out << "property double vx\nproperty double vy\nproperty double vz\n";
    out << "element face " << d.triangles.size() << "\n"
        << "property list uchar int vertex_indices\nend_header\n";
    for (int vi : d.vertices) {
        for (int k = 0; k < 3; ++k)
            put_le<double>(out, mesh.position(vi)[k]);
        if (velocities)
            for (int k = 0; k < 3; ++k)
                put_le<double>(out, (*velocities)[static_cast<size_t>(vi)][k]);
    }
    for (const Triangle& t : d.triangles) {
        put_le<std::uint8_t>(out, 3);
        for (int vi : t)
            put_le<std::int32_t>(out, vi);
    }
    commit_stream(out, path);
}

void write_obj(const std::string& path, const SurfaceMesh& mesh) {
    const DenseMesh d = dense(mesh);
    std::ofstream out = open_temporary(path, std::ios::out);
    out.precision(ROUND_TRIP_DIGITS);
    out << "# written by meniscus\n";
    for (int vi : d.vertices) {
        const Vec3& p = mesh.position(vi);
        out << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
    }
    for (const Triangle& t : d.triangles)
        out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    commit_stream(out, path);
}

MeshData read_ply(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        fail(path, "cannot open for reading");
    std::string line;
    if (!std::getline(in, line) || line.rfind("ply", 0) != 0)
        fail(path, "not a PLY file (no 'ply' magic)");
    PlyFormat format = PlyFormat::Ascii;
    bool have_format = false;
    std::vector<PlyElement> elements;
    while (true) {
        if (!std::getline(in, line))
            fail(path, "PLY header has no end_header");
        if (!line.empty() && line.back() == '\r')
            line.pop_back();
        std::istringstream words(line);
        std::string keyword;
        words >> keyword;
        if (keyword == "end_header")
            break;
        if (keyword == "comment" || keyword == "obj_info" || keyword.empty())
            continue;
        if (keyword == "format") {
            std::string f;
            words >> f;
            if (f == "ascii")
                format = PlyFormat::Ascii;
            else if (f == "binary_little_endian")
                format = PlyFormat::BinaryLittle;
            else if (f == "binary_big_endian")
                format = PlyFormat::BinaryBig;
            else
                fail(path, "unknown PLY format '" + f + "'");
            have_format = true;
        } else if (keyword == "element") {
            PlyElement e;
            if (!(words >> e.name >> e.count) || e.count < 0)
                fail(path, "bad PLY element line: " + line);
            elements.push_back(e);
        } else if (keyword == "property") {
            if (elements.empty())
                fail(path, "PLY property before any element");
            PlyProperty p;
            std::string type;
            words >> type;
            if (type == "list") {
                std::string count_type, item_type;
                words >> count_type >> item_type >> p.name;
                p.is_list = true;
                p.count_type = parse_ply_type(count_type, path);
                p.type = parse_ply_type(item_type, path);
            } else {
                p.type = parse_ply_type(type, path);
                words >> p.name;
            }
            elements.back().properties.push_back(p);
        } else {
            fail(path, "unknown PLY header line: " + line);
        }
    }
    if (!have_format)
        fail(path, "PLY header has no format line");

    // Counts are the file's claims: check them against what is left of it before reading.
    const std::streamoff header_end = in.tellg();
    in.seekg(0, std::ios::end);
    const std::streamoff file_end = in.tellg();
    in.seekg(header_end);
    const double body_bytes = static_cast<double>(file_end - header_end);
    double needed = 0.0;
    for (const PlyElement& e : elements) {
        if (e.count > 0 && e.properties.empty())
            fail(path, "element '" + e.name + "' has no properties");
        const double element_bytes = min_element_bytes(e, format);
        needed += static_cast<double>(e.count) * element_bytes;
        if (needed > body_bytes)
            fail(path, "the header declares " + std::to_string(e.count) + " '" + e.name +
                           "' elements of at least " + std::to_string(static_cast<int>(element_bytes)) +
                           " bytes each, but only " + std::to_string(file_end - header_end) +
                           " bytes follow the header (truncated file or wrong count)");
    }

    MeshData data;
    PlyValueReader reader(in, format, path);
    for (const PlyElement& e : elements) {
        const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
        const int ix = property_index(e, "x"), iy = property_index(e, "y"),
                  iz = property_index(e, "z");
        const int ivx = property_index(e, "vx"), ivy = property_index(e, "vy"),
                  ivz = property_index(e, "vz");
        int ilist = property_index(e, "vertex_indices");
        if (ilist < 0)
            ilist = property_index(e, "vertex_index");
        if (is_vertex && (ix < 0 || iy < 0 || iz < 0))
            fail(path, "PLY vertex element lacks x, y or z");
        if (is_face && ilist < 0)
            fail(path, "PLY face element lacks vertex_indices");
        const bool has_velocity = is_vertex && ivx >= 0 && ivy >= 0 && ivz >= 0;
        for (long long n = 0; n < e.count; ++n) {
            Vec3 p = Vec3::Zero(), v = Vec3::Zero();
            std::vector<long long> poly;
            for (size_t q = 0; q < e.properties.size(); ++q) {
                const PlyProperty& prop = e.properties[q];
                const int qi = static_cast<int>(q);
                if (prop.is_list) {
                    const double count = reader.read(prop.count_type);
                    if (count < 0)
                        fail(path, "negative PLY list length");
                    if (count * min_value_bytes(prop.type, format) > body_bytes)
                        fail(path, e.name + " " + std::to_string(n) + ": a list of " +
                                       std::to_string(static_cast<long long>(count)) +
                                       " entries is longer than the file");
                    std::vector<long long> items(static_cast<size_t>(count));
                    for (auto& item : items)
                        item = static_cast<long long>(reader.read(prop.type));
                    if (is_face && qi == ilist)
                        poly = std::move(items);
                    continue;
                }
                const double value = reader.read(prop.type);
                if (qi == ix)
                    p.x() = value;
                if (qi == iy)
                    p.y() = value;
                if (qi == iz)
                    p.z() = value;
                if (qi == ivx)
                    v.x() = value;
                if (qi == ivy)
                    v.y() = value;
                if (qi == ivz)
                    v.z() = value;
            }
            if (is_vertex) {
                if (!p.allFinite())
                    fail(path, "vertex " + std::to_string(n) + " has a non-finite coordinate");
                data.positions.push_back(p);
                if (has_velocity)
                    data.velocities.push_back(v);
            }
            if (is_face)
                add_polygon(data, poly, path, "face " + std::to_string(n), 0);
        }
    }
    return data;
}

MeshData read_obj(const std::string& path) {
    std::ifstream in(path);
    if (!in)
        fail(path, "cannot open for reading");
    MeshData data;
    std::string line;
    long long line_no = 0;
    while (std::getline(in, line)) {
        ++line_no;
        const std::string where = "line " + std::to_string(line_no);
        std::istringstream words(line);
        std::string keyword;
        words >> keyword;
        if (keyword == "v") {
            Vec3 p;
            if (!(words >> p.x() >> p.y() >> p.z()))
                fail(path, where + ": malformed vertex");
            if (!p.allFinite())
                fail(path, where + ": non-finite vertex coordinate");
            data.positions.push_back(p);
        } else if (keyword == "f") {
            std::vector<long long> poly;
            std::string token;
            while (words >> token) {
                long long index = 0;
                try {
                    index = std::stoll(token.substr(0, token.find('/')));
                } catch (const std::exception&) {
                    fail(path, where + ": malformed face index '" + token + "'");
                }
                if (index == 0)
                    fail(path, where + ": OBJ indices start at 1, got 0");
                poly.push_back(index > 0 ? index - 1
                                         : static_cast<long long>(data.positions.size()) + index);
            }
            add_polygon(data, poly, path, where, 1);
            data.face_line.push_back(line_no);
        }
    }
    return data;
}

MeshData read_mesh_file(const std::string& path) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (std::filesystem::is_directory(status))
        fail(path, "is a directory, not a mesh file");
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
        fail(path, "is not a regular file");
    const auto dot = path.rfind('.');
    const std::string ext = dot == std::string::npos ? "" : lower(path.substr(dot));
    if (ext == ".ply")
        return read_ply(path);
    if (ext == ".obj")
        return read_obj(path);
    fail(path, "unsupported mesh format '" + ext + "' (use .ply or .obj)");
}

SurfaceMesh to_surface_mesh(const MeshData& data, const std::string& source) {
    const int nv = static_cast<int>(data.positions.size());
    for (size_t ti = 0; ti < data.triangles.size(); ++ti) {
        const Triangle& t = data.triangles[ti];
        for (int vi : t)
            if (vi < 0 || vi >= nv)
                fail(source, "triangle " + std::to_string(ti) + " refers to vertex " +
                                 std::to_string(vi) + " but there are " + std::to_string(nv) +
                                 " vertices");
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
            fail(source, "triangle " + std::to_string(ti) + " (" + std::to_string(t[0]) + ", " +
                             std::to_string(t[1]) + ", " + std::to_string(t[2]) +
                             ") repeats a vertex (degenerate triangle)");
    }
    return SurfaceMesh(data.positions, data.triangles);
}

}  // namespace meniscus::tracker
