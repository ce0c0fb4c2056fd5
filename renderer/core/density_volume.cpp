// Density volumes: spec parsing, the built-in generators (Lucent's own hash noise), the
// NRRD subset, the contrast knob and the content hash.
// [SECTION] spec parsing   [SECTION] noise   [SECTION] generators
// [SECTION] NRRD files     [SECTION] volume assembly
#include "renderer/core/density_volume.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <mutex>
#include <optional>
#include <sstream>

#include "common/content_hash.h"
#include "common/number_text.h"

namespace lucent {
namespace {

constexpr double kPi = 3.14159265358979323846;

[[noreturn]] void fail(const std::string& what) {
    throw DensityError("density: " + what);
}

// [SECTION] spec parsing

struct ParameterRange {
    std::string name;
    double default_value, min, max;
};

const std::map<std::string, std::vector<ParameterRange>>& generators() {
    static const std::map<std::string, std::vector<ParameterRange>> table = {
        {"constant", {{"value", 0.5, 0, 1}}},
        {"cube", {{"size", 0.5, 0, 1}, {"inside", 1, 0, 1}, {"outside", 0, 0, 1}}},
        {"spheres",
         {{"count", 6, 1, 64},
          {"radius", 0.15, 0.01, 1},
          {"inside", 1, 0, 1},
          {"outside", 0.2, 0, 1},
          {"seed", 1, 0, 1e9}}},
        {"marble",
         {{"frequency", 3, 0, 64},
          {"turbulence", 2, 0, 64},
          {"octaves", 4, 1, 8},
          {"seed", 1, 0, 1e9}}},
        {"layers", {{"count", 4, 0, 64}, {"axis", 2, 0, 2}}},
    };
    return table;
}

std::string list_of(const std::vector<std::string>& names) {
    std::string text;
    for (const auto& n : names) text += (text.empty() ? "" : ", ") + n;
    return text;
}

bool ends_with(std::string_view text, std::string_view suffix) {
    return text.size() >= suffix.size() &&
           text.substr(text.size() - suffix.size()) == suffix;
}

// [SECTION] noise: SplitMix64 of the lattice point, value noise with a quintic fade.

std::uint64_t mix64(std::uint64_t z) {
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

// Uniform in [0, 1) from the integer hash: 53 bits, exact on every machine.
double hash_unit(std::uint64_t seed, std::int64_t x, std::int64_t y, std::int64_t z) {
    std::uint64_t h = mix64(seed);
    h = mix64(h ^ std::uint64_t(x));
    h = mix64(h ^ std::uint64_t(y));
    h = mix64(h ^ std::uint64_t(z));
    return double(h >> 11) * (1.0 / 9007199254740992.0);
}

double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }

double value_noise(std::uint64_t seed, glm::dvec3 p) {
    const glm::dvec3 cell = glm::floor(p), f = p - cell;
    const auto ix = std::int64_t(cell.x), iy = std::int64_t(cell.y),
               iz = std::int64_t(cell.z);
    const double u = fade(f.x), v = fade(f.y), w = fade(f.z);
    double sum = 0.0;
    for (int k = 0; k < 8; ++k) {
        const int dx = k & 1, dy = (k >> 1) & 1, dz = k >> 2;
        const double weight = (dx ? u : 1 - u) * (dy ? v : 1 - v) * (dz ? w : 1 - w);
        sum += weight * hash_unit(seed, ix + dx, iy + dy, iz + dz);
    }
    return sum;  // [0, 1]
}

// Turbulence: sum of |2 noise - 1| over octaves, halving amplitude, doubling frequency.
double turbulence(std::uint64_t seed, glm::dvec3 p, int octaves) {
    double sum = 0.0, amplitude = 1.0, norm = 0.0;
    for (int o = 0; o < octaves; ++o) {
        sum += amplitude * std::abs(2.0 * value_noise(seed + std::uint64_t(o), p) - 1.0);
        norm += amplitude;
        p *= 2.0;
        amplitude *= 0.5;
    }
    return sum / norm;  // [0, 1]
}

// [SECTION] generators: rho at the voxel centre t in [0, 1]^3.

std::vector<float> generate(const DensitySpec& spec, int r) {
    const auto& p = spec.parameters;
    const auto param = [&](const char* name) { return p.at(name); };
    std::vector<float> voxels(std::size_t(r) * r * r);
    // Sphere centres and radii are drawn once, from the seed.
    std::vector<glm::dvec4> spheres;
    if (spec.generator == "spheres") {
        const auto seed = std::uint64_t(param("seed"));
        for (int i = 0; i < int(param("count")); ++i)
            spheres.push_back({hash_unit(seed, i, 0, 1), hash_unit(seed, i, 1, 1),
                               hash_unit(seed, i, 2, 1),
                               param("radius") * (0.5 + 0.5 * hash_unit(seed, i, 3, 1))});
    }
    for (int z = 0; z < r; ++z)
        for (int y = 0; y < r; ++y)
            for (int x = 0; x < r; ++x) {
                const glm::dvec3 t = (glm::dvec3(x, y, z) + 0.5) / double(r);
                double rho = 0.0;
                if (spec.generator == "constant") {
                    rho = param("value");
                } else if (spec.generator == "cube") {
                    const double half = 0.5 * param("size");
                    const glm::dvec3 d = glm::abs(t - 0.5);
                    rho = std::max({d.x, d.y, d.z}) < half ? param("inside")
                                                           : param("outside");
                } else if (spec.generator == "spheres") {
                    rho = param("outside");
                    for (const glm::dvec4& s : spheres)
                        if (glm::length(t - glm::dvec3(s)) < s.w) rho = param("inside");
                } else if (spec.generator == "marble") {
                    const double turb = turbulence(std::uint64_t(param("seed")), t * 4.0,
                                                   int(param("octaves")));
                    rho = 0.5 + 0.5 * std::sin(2.0 * kPi * param("frequency") * t.x +
                                               param("turbulence") * 2.0 * kPi * turb);
                } else if (spec.generator == "layers") {
                    rho = 0.5 + 0.5 * std::cos(2.0 * kPi * param("count") *
                                               t[int(param("axis"))]);
                }
                // Quantise the trigonometric generators to 2^-20 so a last-bit
                // difference of sin/cos between C libraries cannot change the hash.
                rho = std::clamp(rho, 0.0, 1.0);
                if (spec.generator == "marble" || spec.generator == "layers")
                    rho = std::round(rho * 1048576.0) / 1048576.0;
                voxels[(std::size_t(z) * r + y) * r + x] = float(rho);
            }
    return voxels;
}

// [SECTION] NRRD files (the documented subset)

// An NRRD file's voxels from its bytes in `in` (`path` names the file in errors).
std::vector<float> read_nrrd(std::istream& in, const std::string& path,
                             glm::ivec3& size) {
    const auto bad = [&](const std::string& what) { fail(path + ": " + what); };
    std::string line;
    if (!std::getline(in, line) || line.rfind("NRRD", 0) != 0)
        bad("not an NRRD file (the first line must be NRRD000N)");
    std::map<std::string, std::string> fields;
    while (std::getline(in, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) break;  // the header ends at the first blank line
        if (line[0] == '#') continue;
        const auto colon = line.find(": ");
        if (colon == std::string::npos) {
            if (line.find(":=") != std::string::npos) continue;  // key/value comment
            bad("header line '" + line + "' is not 'field: value'");
        }
        fields[line.substr(0, colon)] = line.substr(colon + 2);
    }
    const auto field = [&](const std::string& name) -> std::string {
        const auto it = fields.find(name);
        if (it == fields.end()) bad("field '" + name + "' is missing");
        return it->second;
    };
    if (field("dimension") != "3")
        bad("field 'dimension': '" + fields["dimension"] + "' (only 3)");
    const std::string type = field("type");
    const bool bytes = type == "uchar" || type == "unsigned char" || type == "uint8" ||
                       type == "uint8_t";
    if (!bytes && type != "float")
        bad("field 'type': '" + type + "' (only uchar or float)");
    if (const std::string e = field("encoding"); e != "raw")
        bad("field 'encoding': '" + e + "' (only raw)");
    if (!bytes) {
        if (const std::string e = field("endian"); e != "little")
            bad("field 'endian': '" + e + "' (only little)");
    }
    if (fields.count("data file"))
        bad("field 'data file': detached data is not supported");
    std::istringstream sizes(field("sizes"));
    for (int a = 0; a < 3; ++a) {
        long long s = 0;
        if (!(sizes >> s) || s < 1 || s > 1024)
            bad("field 'sizes': '" + fields["sizes"] + "' (three integers in [1, 1024])");
        size[a] = int(s);
    }
    const std::size_t count = std::size_t(size.x) * size.y * size.z;
    std::vector<float> voxels(count);
    if (bytes) {
        std::vector<unsigned char> raw(count);
        in.read(reinterpret_cast<char*>(raw.data()), std::streamsize(count));
        if (std::size_t(in.gcount()) != count)
            bad("data: " + std::to_string(in.gcount()) + " bytes, expected " +
                std::to_string(count));
        for (std::size_t i = 0; i < count; ++i) voxels[i] = float(raw[i]) / 255.0f;
    } else {
        in.read(reinterpret_cast<char*>(voxels.data()), std::streamsize(count * 4));
        if (std::size_t(in.gcount()) != count * 4)
            bad("data: " + std::to_string(in.gcount()) + " bytes, expected " +
                std::to_string(count * 4));
        for (std::size_t i = 0; i < count; ++i)
            if (!(voxels[i] >= 0.0f && voxels[i] <= 1.0f)) {
                const std::size_t x = i % size.x, y = (i / size.x) % size.y,
                                  z = i / (std::size_t(size.x) * size.y);
                std::ostringstream text;
                text << "voxel (" << x << ", " << y << ", " << z << "): " << voxels[i]
                     << " is not a density in [0, 1]";
                bad(text.str());
            }
    }
    return voxels;
}

std::vector<float> read_nrrd(const std::string& path, glm::ivec3& size) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(path + ": cannot open the file");
    return read_nrrd(in, path, size);
}

// A whole file's bytes; nullopt when it cannot be read.
std::optional<std::string> file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return std::nullopt;
    std::ostringstream bytes;
    bytes << in.rdbuf();
    if (in.bad()) return std::nullopt;
    return std::move(bytes).str();
}

std::string hash_of(glm::ivec3 size, const std::vector<float>& voxels) {
    common::ContentHash hash;
    for (int a = 0; a < 3; ++a) hash.word(std::uint32_t(size[a]));
    for (float v : voxels) hash.float_bits(v);  // -0 and +0 hash alike
    return hash.hex();
}

}  // namespace

const std::vector<std::string>& density_generator_names() {
    static const std::vector<std::string> names = [] {
        std::vector<std::string> n;
        for (const auto& [name, ranges] : generators()) n.push_back(name);
        return n;
    }();
    return names;
}

DensitySpec parse_density_spec(std::string_view text) {
    DensitySpec spec;
    if (ends_with(text, ".nrrd") || ends_with(text, ".nhdr")) {
        if (ends_with(text, ".nhdr"))
            fail(std::string(text) + ": detached headers (.nhdr) are not supported");
        spec.file = std::string(text);
        return spec;
    }
    const auto colon = text.find(':');
    spec.generator = std::string(text.substr(0, colon));
    const auto it = generators().find(spec.generator);
    if (it == generators().end())
        fail("'" + spec.generator + "' is not a generator (valid: " +
             list_of(density_generator_names()) + ") or an .nrrd file");
    for (const auto& range : it->second)
        spec.parameters[range.name] = range.default_value;
    if (colon == std::string_view::npos) return spec;
    std::string_view rest = text.substr(colon + 1);
    while (!rest.empty()) {
        const auto comma = rest.find(',');
        const std::string_view item = rest.substr(0, comma);
        rest =
            comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
        const auto equals = item.find('=');
        const std::string key(item.substr(0, equals));
        const auto range =
            std::find_if(it->second.begin(), it->second.end(),
                         [&](const ParameterRange& r) { return r.name == key; });
        if (equals == std::string_view::npos || range == it->second.end()) {
            std::vector<std::string> names;
            for (const auto& r : it->second) names.push_back(r.name);
            fail(spec.generator + ": '" + std::string(item) +
                 "' is not name=value for a parameter (" + list_of(names) + ")");
        }
        std::string_view value_text = item.substr(equals + 1);
        double value = 0;
        if (key == "axis" && value_text.size() == 1 && value_text[0] >= 'x' &&
            value_text[0] <= 'z')
            value = value_text[0] - 'x';
        else if (const auto number = common::parse_finite(value_text);
                 number && *number >= range->min && *number <= range->max)
            value = *number;
        else
            fail(spec.generator + ": " + key + " '" + std::string(value_text) +
                 "' is not a number in [" + std::to_string(range->min) + ", " +
                 std::to_string(range->max) + "]");
        if ((key == "count" || key == "octaves" || key == "seed") &&
            value != std::floor(value))
            fail(spec.generator + ": " + key + " '" + std::string(value_text) +
                 "' is not a whole number");
        spec.parameters[key] = value;
    }
    return spec;
}

double DensityVolume::sample(glm::dvec3 t) const {
    const glm::dvec3 p = t * glm::dvec3(size) - 0.5;
    const glm::dvec3 cell = glm::floor(p), f = p - cell;
    const glm::ivec3 i0(cell);
    double sum = 0.0;
    for (int k = 0; k < 8; ++k) {
        const glm::ivec3 d(k & 1, (k >> 1) & 1, k >> 2);
        const glm::ivec3 i = glm::clamp(i0 + d, glm::ivec3(0), size - 1);
        const double weight =
            (d.x ? f.x : 1 - f.x) * (d.y ? f.y : 1 - f.y) * (d.z ? f.z : 1 - f.z);
        sum += weight * voxel(i.x, i.y, i.z);
    }
    return sum;
}

DensityVolume finish_density_volume(glm::ivec3 size, std::vector<float> voxels,
                                    std::string spec) {
    DensityVolume v;
    v.size = size;
    v.voxels = std::move(voxels);
    v.spec = std::move(spec);
    double sum = 0.0;
    v.min = 1.0f;
    v.max = 0.0f;
    for (float x : v.voxels) {
        sum += x;
        v.min = std::min(v.min, x);
        v.max = std::max(v.max, x);
    }
    v.mean = v.voxels.empty() ? 0.0f : float(sum / double(v.voxels.size()));
    v.content_hash = hash_of(v.size, v.voxels);
    return v;
}

namespace {

// make_density_volume, a file's volume from `bytes` when given (the bytes its cache key
// was made of), else read from the file.
std::shared_ptr<const DensityVolume> build_density_volume(std::string_view text,
                                                          int resolution, double contrast,
                                                          const std::string* bytes) {
    const DensitySpec spec = parse_density_spec(text);
    glm::ivec3 size(resolution);
    std::vector<float> voxels;
    if (!spec.file.empty()) {
        if (bytes) {
            std::istringstream in(*bytes);
            voxels = read_nrrd(in, spec.file, size);
        } else {
            voxels = read_nrrd(spec.file, size);
        }
    } else {
        if (resolution < 1 || resolution > 512)
            fail("resolution " + std::to_string(resolution) + " is not in [1, 512]");
        voxels = generate(spec, resolution);
    }
    // The contrast knob around the volume's own mean; c = 0 makes it exactly constant.
    if (contrast != 1.0) {
        double sum = 0.0;
        for (float x : voxels) sum += x;
        const float mean = float(sum / double(voxels.size()));
        for (float& x : voxels)
            x = contrast == 0.0
                    ? mean
                    : std::clamp(float(mean + contrast * (x - mean)), 0.0f, 1.0f);
    }
    return std::make_shared<const DensityVolume>(
        finish_density_volume(size, std::move(voxels), std::string(text)));
}

}  // namespace

std::shared_ptr<const DensityVolume> make_density_volume(std::string_view text,
                                                         int resolution,
                                                         double contrast) {
    return build_density_volume(text, resolution, contrast, nullptr);
}

void write_density_nrrd(const DensityVolume& volume, const std::string& path) {
    std::ofstream out(path, std::ios::binary);
    out << "NRRD0004\n# written by lucent\ntype: float\ndimension: 3\nsizes: "
        << volume.size.x << " " << volume.size.y << " " << volume.size.z
        << "\nencoding: raw\nendian: little\n\n";
    out.write(reinterpret_cast<const char*>(volume.voxels.data()),
              std::streamsize(volume.voxels.size() * sizeof(float)));
    if (!out) fail(path + ": cannot write the file");
}

std::shared_ptr<const DensityVolume> density_from_knobs(const KnobValues& values) {
    if (!values.contains("density")) return nullptr;
    const std::string& spec = values.choice("density");
    const int resolution = std::stoi(values.choice("density_resolution"));
    const double contrast = values.scalar("density_contrast");
    // The last few volumes, so the explorer (a scene per frame) and batch rendering (a
    // scene per stimulus) build each once. A file's key is its bytes (their size and
    // FNV-1a hash), never its size and modification time: a file rewritten within
    // a coarse timestamp's tick, or given its old time back, is another volume.
    std::string key =
        spec + "|" + std::to_string(resolution) + "|" + std::to_string(contrast);
    std::optional<std::string> bytes;
    if (ends_with(spec, ".nrrd")) {
        bytes = file_bytes(spec);
        // Unreadable: make_density_volume says why, and nothing is cached.
        if (!bytes) return make_density_volume(spec, resolution, contrast);
        key += "|" + std::to_string(bytes->size()) + "|" +
               common::ContentHash().bytes(*bytes).hex();
    }
    static std::mutex mutex;
    static std::vector<std::pair<std::string, std::shared_ptr<const DensityVolume>>>
        cache;
    {
        std::lock_guard lock(mutex);
        for (const auto& [k, volume] : cache)
            if (k == key) return volume;
    }
    auto volume =
        build_density_volume(spec, resolution, contrast, bytes ? &*bytes : nullptr);
    std::lock_guard lock(mutex);
    cache.insert(cache.begin(), {key, volume});
    if (cache.size() > 8) cache.pop_back();
    return volume;
}

}  // namespace lucent
