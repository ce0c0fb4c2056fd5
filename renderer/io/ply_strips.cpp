// PLY files that store their surface as triangle strips ('element tristrips', a list of
// vertex indices with -1 restarting the strip), as the Igea scan does. Assimp 5.2 reads
// them as one bogus triangle, so they are read here: ASCII or binary little-endian.
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "renderer/core/mesh.h"
#include "renderer/io/mesh_sources.h"

namespace lucent {

namespace {

struct Property {
    std::string name;
    std::string type;        // scalar type, or the list's item type
    std::string count_type;  // non-empty for a list
};
struct Element {
    std::string name;
    std::size_t count = 0;
    std::vector<Property> properties;
};

int type_size(const std::string& type) {
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16")
        return 2;
    if (type == "int" || type == "uint" || type == "int32" || type == "uint32" ||
        type == "float" || type == "float32")
        return 4;
    if (type == "double" || type == "float64") return 8;
    return 0;
}

// Reads values one at a time from the body, whichever encoding it has.
class BodyReader {
public:
    BodyReader(const std::string& path, std::string body, bool binary)
        : path_(path), body_(std::move(body)), binary_(binary), text_(body_) {}

    double read(const std::string& type) {
        if (!binary_) {
            double value = 0.0;
            if (!(text_ >> value))
                throw MeshError(path_ + ": PLY body ends early or is not numeric");
            return value;
        }
        const int size = type_size(type);
        if (offset_ + size > body_.size())
            throw MeshError(path_ + ": PLY body is truncated");
        const char* p = body_.data() + offset_;
        offset_ += size;
        auto as = [p](auto value) {
            std::memcpy(&value, p, sizeof value);
            return double(value);
        };
        if (type == "char" || type == "int8") return as(std::int8_t{});
        if (type == "uchar" || type == "uint8") return as(std::uint8_t{});
        if (type == "short" || type == "int16") return as(std::int16_t{});
        if (type == "ushort" || type == "uint16") return as(std::uint16_t{});
        if (type == "int" || type == "int32") return as(std::int32_t{});
        if (type == "uint" || type == "uint32") return as(std::uint32_t{});
        if (type == "float" || type == "float32") return as(float{});
        return as(double{});
    }

private:
    std::string path_;
    std::string body_;
    bool binary_;
    std::size_t offset_ = 0;
    std::istringstream text_;
};

}  // namespace

std::optional<RawMesh> read_ply_triangle_strips(const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    std::string line;
    if (!std::getline(file, line) || (line != "ply" && line != "ply\r"))
        return std::nullopt;

    // Header.
    std::string format;
    std::vector<Element> elements;
    while (std::getline(file, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream words(line);
        std::string keyword;
        words >> keyword;
        if (keyword == "end_header") break;
        if (keyword == "format")
            words >> format;
        else if (keyword == "element") {
            Element element;
            words >> element.name >> element.count;
            elements.push_back(element);
        } else if (keyword == "property" && !elements.empty()) {
            Property property;
            words >> property.type;
            if (property.type == "list") words >> property.count_type >> property.type;
            words >> property.name;
            if (type_size(property.type) == 0 ||
                (!property.count_type.empty() && type_size(property.count_type) == 0))
                throw MeshError(path + ": PLY property '" + property.name +
                                "' has an unknown type");
            elements.back().properties.push_back(property);
        }
    }
    bool has_strips = false;
    for (const Element& e : elements) has_strips = has_strips || e.name == "tristrips";
    if (!has_strips) return std::nullopt;
    if (format != "ascii" && format != "binary_little_endian")
        throw MeshError(path +
                        ": PLY triangle strips are read only from ascii or "
                        "binary_little_endian files, not " +
                        format);

    std::string body((std::istreambuf_iterator<char>(file)),
                     std::istreambuf_iterator<char>());
    BodyReader reader(path, std::move(body), format != "ascii");
    RawMesh raw;
    for (const Element& element : elements) {
        for (std::size_t item = 0; item < element.count; ++item) {
            glm::vec3 position(0.0f), normal(0.0f);
            for (const Property& property : element.properties) {
                if (property.count_type.empty()) {
                    const double value = reader.read(property.type);
                    const std::string& n = property.name;
                    if (n == "x")
                        position.x = float(value);
                    else if (n == "y")
                        position.y = float(value);
                    else if (n == "z")
                        position.z = float(value);
                    else if (n == "nx")
                        normal.x = float(value);
                    else if (n == "ny")
                        normal.y = float(value);
                    else if (n == "nz")
                        normal.z = float(value);
                    continue;
                }
                const double count = reader.read(property.count_type);
                if (count < 0 || count > 1e9)
                    throw MeshError(path + ": PLY list length is invalid");
                std::vector<long long> indices(static_cast<std::size_t>(count));
                for (long long& index : indices)
                    index = static_cast<long long>(reader.read(property.type));
                if (element.name == "tristrips") {
                    // Each strip alternates its winding; -1 starts a new strip.
                    std::size_t strip_start = 0;
                    for (std::size_t k = 0; k < indices.size(); ++k) {
                        if (indices[k] < 0) {
                            strip_start = k + 1;
                            continue;
                        }
                        if (k < strip_start + 2) continue;
                        const long long a = indices[k - 2], b = indices[k - 1],
                                        c = indices[k];
                        ++raw.faces_in_file;
                        if (a == b || b == c || a == c) continue;  // strip joints
                        if ((k - strip_start) % 2 == 0)
                            raw.triangles.emplace_back(a, b, c);
                        else
                            raw.triangles.emplace_back(b, a, c);
                    }
                } else if (element.name == "face") {
                    ++raw.faces_in_file;
                    for (std::size_t k = 2; k < indices.size(); ++k)  // fan
                        raw.triangles.emplace_back(indices[0], indices[k - 1],
                                                   indices[k]);
                }
            }
            if (element.name == "vertex") {
                raw.positions.push_back(position);
                raw.normals.push_back(normal);
            }
        }
    }
    bool has_normals = false;
    for (const Element& e : elements)
        if (e.name == "vertex")
            for (const Property& p : e.properties)
                has_normals = has_normals || p.name == "nx";
    if (!has_normals) raw.normals.clear();
    return raw;
}

}  // namespace lucent
