// Built-in procedural meshes, so every feature works without mesh files. Each takes a
// face budget ("torus_knot:240k") and lands within a few percent of it.
//   sphere      unit radius, poles on the Z axis (the default camera's central ray
//               passes through both poles, so its thickness there is exactly 2)
//   torus       major radius 1, tube radius 0.4, axis Y (seen side-on by default)
//   torus_knot  (2,3) trefoil tube whose radius varies from 0.05 to 0.25 (thin and thick)
//   hand        palm, four fingers, a thumb and a wrist smoothly merged (non-convex, thin
//               protrusions; stand-in for the thesis's hand and Fertility models);
//               polygonised, so budgets under ~1000 faces are met only roughly
// Open sheets with texture coordinates whose texels are square in world space (for the
// thick_texture technique), 2 x 2 units, facing +Z, uv = world distance / 2:
//   square      flat grid at z = 0 (default 2 triangles, the thesis's Square)
//   wave        a curtain z = 0.12 sin(2 pi x), u = arc length along x / 2 (default 800
//               triangles, the thesis's Wave1; wave:12800 is Wave2)
//   drape       doubly curved z = 0.2 sin(pi x) sin(pi y), uv = ((x, y) + 1) / 2: not
//               developable, so its texels are not square (a robustness case)
#include "renderer/core/mesh_builtin.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>
#include <numbers>

#include "renderer/core/mesh.h"
#include "renderer/core/polygonise.h"

namespace lucent {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr std::size_t kMinFaceBudget = 100;
constexpr std::size_t kMaxFaceBudget = 20'000'000;

double signed_volume(const Mesh& mesh) {
    double six_volume = 0.0;
    for (const glm::uvec3& t : mesh.triangles)
        six_volume += glm::dot(
            glm::dvec3(mesh.positions[t.x]),
            glm::cross(glm::dvec3(mesh.positions[t.y]), glm::dvec3(mesh.positions[t.z])));
    return six_volume / 6.0;
}

// Flips every triangle when the (consistently wound) mesh encloses negative volume.
void orient_outward(Mesh& mesh) {
    if (signed_volume(mesh) >= 0.0) return;
    for (glm::uvec3& t : mesh.triangles) std::swap(t.y, t.z);
}

// Two triangles per cell of a (rows x columns) vertex grid that wraps around in both
// directions; vertex (i, j) has index i * columns + j. Counter-clockwise seen from the
// side that d(row) x d(column) points to.
void add_wrapped_grid(Mesh& mesh, unsigned rows, unsigned columns) {
    for (unsigned i = 0; i < rows; ++i)
        for (unsigned j = 0; j < columns; ++j) {
            const unsigned i1 = (i + 1) % rows, j1 = (j + 1) % columns;
            const unsigned a = i * columns + j, b = i1 * columns + j;
            const unsigned c = i1 * columns + j1, d = i * columns + j1;
            mesh.triangles.push_back({a, b, c});
            mesh.triangles.push_back({a, c, d});
        }
}

// Picks (count_a, count_b) with 2 * a * b close to `faces` and a / b close to `ratio`;
// a is rounded to a multiple of `a_multiple`, b to a multiple of `b_multiple`.
std::pair<unsigned, unsigned> grid_for_budget(std::size_t faces, double ratio,
                                              unsigned a_multiple, unsigned b_multiple) {
    const double ideal_b = std::sqrt(static_cast<double>(faces) / (2.0 * ratio));
    std::pair<unsigned, unsigned> best{0, 0};
    double best_error = 1e300;
    for (int db = -4; db <= 4; ++db) {
        const long b = (std::lround(ideal_b / b_multiple) + db) * b_multiple;
        if (b < 3) continue;
        const long a = std::max<long>(
            3, std::lround(static_cast<double>(faces) / (2.0 * b * a_multiple)) *
                   a_multiple);
        const double error = std::abs(2.0 * a * b - static_cast<double>(faces));
        if (error < best_error) best_error = error, best = {unsigned(a), unsigned(b)};
    }
    return best;
}

Mesh make_sphere(std::size_t budget) {
    // UV sphere: 2 * slices * (stacks - 1) faces, poles at z = +-1.
    const auto [slices, rings] =
        grid_for_budget(budget, 2.0, 4, 1);  // rings = stacks - 1
    const unsigned stacks = rings + 1;
    Mesh mesh;
    mesh.positions.push_back({0.0f, 0.0f, 1.0f});
    for (unsigned i = 1; i < stacks; ++i) {
        const double theta = kPi * i / stacks;
        for (unsigned j = 0; j < slices; ++j) {
            const double phi = 2.0 * kPi * j / slices;
            mesh.positions.push_back(
                glm::vec3(glm::dvec3(std::sin(theta) * std::cos(phi),
                                     std::sin(theta) * std::sin(phi), std::cos(theta))));
        }
    }
    mesh.positions.push_back({0.0f, 0.0f, -1.0f});
    const unsigned south = static_cast<unsigned>(mesh.positions.size() - 1);
    auto ring_vertex = [&](unsigned ring, unsigned j) {
        return 1 + ring * slices + j % slices;
    };
    for (unsigned j = 0; j < slices; ++j) {
        mesh.triangles.push_back({0, ring_vertex(0, j), ring_vertex(0, j + 1)});
        mesh.triangles.push_back(
            {south, ring_vertex(stacks - 2, j + 1), ring_vertex(stacks - 2, j)});
    }
    for (unsigned ring = 0; ring + 1 < stacks - 1; ++ring)
        for (unsigned j = 0; j < slices; ++j) {
            const unsigned a = ring_vertex(ring, j), b = ring_vertex(ring + 1, j);
            const unsigned c = ring_vertex(ring + 1, j + 1), d = ring_vertex(ring, j + 1);
            mesh.triangles.push_back({a, b, c});
            mesh.triangles.push_back({a, c, d});
        }
    mesh.normals = mesh.positions;  // unit sphere: the analytic normal is the position
    return mesh;
}

Mesh make_torus(std::size_t budget) {
    constexpr double major = 1.0, minor = 0.4;
    // Multiples of 4 around the axis and of 2 around the tube put vertices exactly on
    // the X and Z axes' crossings with the tube, so axis-aligned rays have exact hits.
    const auto [around_axis, around_tube] = grid_for_budget(budget, major / minor, 4, 2);
    Mesh mesh;
    for (unsigned i = 0; i < around_axis; ++i) {
        const double phi = 2.0 * kPi * i / around_axis;
        const glm::dvec3 radial(std::cos(phi), 0.0, -std::sin(phi));
        for (unsigned j = 0; j < around_tube; ++j) {
            const double theta = 2.0 * kPi * j / around_tube;
            const glm::dvec3 normal =
                std::cos(theta) * radial + glm::dvec3(0, std::sin(theta), 0);
            mesh.positions.push_back(glm::vec3(major * radial + minor * normal));
            mesh.normals.push_back(glm::vec3(normal));
        }
    }
    add_wrapped_grid(mesh, around_axis, around_tube);
    orient_outward(mesh);
    return mesh;
}

Mesh make_torus_knot(std::size_t budget) {
    // (2,3) torus knot on a torus of radii (1, 0.45): strands stay >= 0.89 apart and the
    // curve's radius of curvature >= 0.73, so a tube of radius <= 0.25 never intersects
    // itself. The radius swings between 0.05 and 0.25 three times along the knot.
    constexpr double major = 1.0, minor = 0.45, p = 2.0, q = 3.0;
    auto curve = [&](double t) {
        const double r = major + minor * std::cos(q * t);
        return glm::dvec3(r * std::cos(p * t), r * std::sin(p * t),
                          minor * std::sin(q * t));
    };
    auto tangent = [&](double t) {
        const double r = major + minor * std::cos(q * t);
        const double dr = -q * minor * std::sin(q * t);
        return glm::normalize(glm::dvec3(dr * std::cos(p * t) - p * r * std::sin(p * t),
                                         dr * std::sin(p * t) + p * r * std::cos(p * t),
                                         q * minor * std::cos(q * t)));
    };
    auto tube_radius = [](double t) { return 0.15 + 0.10 * std::sin(3.0 * t + 0.5); };
    // Knot length ~13.9, mean tube circumference ~0.94: keep cells roughly square.
    const auto [along, around] = grid_for_budget(budget, 14.0, 1, 1);
    Mesh mesh;
    for (unsigned i = 0; i < along; ++i) {
        const double t = 2.0 * kPi * i / along;
        const glm::dvec3 centre = curve(t), direction = tangent(t);
        // Frame from the torus core circle: periodic, so the tube closes without twist.
        const glm::dvec3 core = major * glm::dvec3(std::cos(p * t), std::sin(p * t), 0.0);
        const glm::dvec3 out = centre - core;
        const glm::dvec3 normal =
            glm::normalize(out - glm::dot(out, direction) * direction);
        const glm::dvec3 binormal = glm::cross(direction, normal);
        for (unsigned j = 0; j < around; ++j) {
            const double theta = 2.0 * kPi * j / around;
            mesh.positions.push_back(
                glm::vec3(centre + tube_radius(t) * (std::cos(theta) * normal +
                                                     std::sin(theta) * binormal)));
        }
    }
    add_wrapped_grid(mesh, along, around);
    orient_outward(mesh);
    return mesh;
}

// ---- hand: a signed distance field polygonised by marching tetrahedra ----

float smooth_min(float a, float b,
                 float k) {  // polynomial smooth minimum (blend width k)
    const float h = std::clamp(0.5f + 0.5f * (b - a) / k, 0.0f, 1.0f);
    return b + (a - b) * h - k * h * (1.0f - h);
}

float capsule(glm::vec3 p, glm::vec3 a, glm::vec3 b, float radius) {
    const glm::vec3 pa = p - a, ba = b - a;
    const float h = std::clamp(glm::dot(pa, ba) / glm::dot(ba, ba), 0.0f, 1.0f);
    return glm::length(pa - ba * h) - radius;
}

float ellipsoid(glm::vec3 p, glm::vec3 radii) {  // a bound, exact on the surface
    const float k0 = glm::length(p / radii), k1 = glm::length(p / (radii * radii));
    return k1 > 0.0f ? k0 * (k0 - 1.0f) / k1 : -std::min({radii.x, radii.y, radii.z});
}

// Negative inside. Palm faces +Z, fingers point to +Y, thumb to -X.
float hand_distance(glm::vec3 p) {
    float d = ellipsoid(p, {0.55f, 0.62f, 0.2f});
    d = smooth_min(d, capsule(p, {0.0f, -0.45f, 0.0f}, {0.0f, -1.15f, 0.0f}, 0.26f),
                   0.15f);
    struct Finger {
        glm::vec3 base, tip;
        float radius;
    };
    const Finger fingers[] = {
        {{-0.34f, 0.42f, 0.0f}, {-0.46f, 1.30f, 0.03f}, 0.085f},    // index
        {{-0.11f, 0.50f, 0.0f}, {-0.13f, 1.45f, 0.04f}, 0.09f},     // middle
        {{0.12f, 0.48f, 0.0f}, {0.20f, 1.36f, 0.03f}, 0.085f},      // ring
        {{0.34f, 0.38f, 0.0f}, {0.52f, 1.08f, 0.02f}, 0.07f},       // little
        {{-0.42f, -0.15f, 0.05f}, {-1.02f, 0.35f, 0.12f}, 0.095f},  // thumb
    };
    for (const Finger& f : fingers)
        d = smooth_min(d, capsule(p, f.base, f.tip, f.radius), 0.06f);
    return d;
}

glm::vec3 distance_gradient(const std::function<float(glm::vec3)>& field, glm::vec3 p,
                            float step) {
    const glm::vec3 dx(step, 0, 0), dy(0, step, 0), dz(0, 0, step);
    return {field(p + dx) - field(p - dx), field(p + dy) - field(p - dy),
            field(p + dz) - field(p - dz)};
}

Mesh make_hand(std::size_t budget) {
    const glm::vec3 lo(-1.25f, -1.5f, -0.35f), hi(0.75f, 1.6f, 0.4f);
    // Faces scale as 1 / cell^2: start from a measured constant and correct the cell
    // size until the count is within 1% of the budget; the count is a noisy function of
    // the cell size at small budgets, so then try a few sizes around the best one.
    Mesh best;
    float best_cell = 0.0f;
    auto error_of = [budget](const Mesh& m) {
        return m.triangles.empty()
                   ? 1e30
                   : std::abs(double(m.face_count()) / double(budget) - 1.0);
    };
    auto consider = [&](float cell) {
        Mesh mesh = polygonise(hand_distance, lo - 2.0f * cell, hi + 2.0f * cell, cell);
        const std::size_t faces = mesh.face_count();
        if (best_cell == 0.0f || error_of(mesh) < error_of(best))
            best = std::move(mesh), best_cell = cell;
        return faces;
    };
    float cell = 7.4f / std::sqrt(static_cast<float>(budget));
    for (int pass = 0; pass < 6 && (best_cell == 0.0f || error_of(best) > 0.01); ++pass) {
        const std::size_t faces = consider(cell);
        // Damped: at very coarse cells whole parts (the palm is 0.4 thick) drop out.
        cell *= faces == 0
                    ? 0.5f
                    : std::clamp(static_cast<float>(std::sqrt(double(faces) / budget)),
                                 0.6f, 1.6f);
    }
    for (int step = -8; step <= 8 && error_of(best) > 0.01; ++step)
        consider(best_cell * (1.0f + 0.01f * static_cast<float>(step)));
    if (best.triangles.empty()) throw MeshError("hand: no surface at this face budget");
    best.normals.resize(best.positions.size());
    for (std::size_t i = 0; i < best.positions.size(); ++i)
        best.normals[i] =
            glm::normalize(distance_gradient(hand_distance, best.positions[i], 1e-3f));
    return best;
}

// A sheet of (columns x rows) cells over x, y in [-1, 1]: z = height(x, y) and the uv
// of each vertex from `uv(x, y)`, two triangles per cell, counter-clockwise from +Z.
Mesh make_sheet(unsigned columns, unsigned rows,
                const std::function<double(double, double)>& height,
                const std::function<glm::dvec2(double, double)>& uv) {
    Mesh mesh;
    for (unsigned i = 0; i <= rows; ++i)
        for (unsigned j = 0; j <= columns; ++j) {
            const double x = -1.0 + 2.0 * j / columns, y = -1.0 + 2.0 * i / rows;
            mesh.positions.emplace_back(x, y, height(x, y));
            mesh.uvs.push_back(glm::vec2(uv(x, y)));
        }
    for (unsigned i = 0; i < rows; ++i)
        for (unsigned j = 0; j < columns; ++j) {
            const unsigned a = i * (columns + 1) + j, b = a + 1;
            const unsigned c = b + columns + 1, d = a + columns + 1;
            mesh.triangles.push_back({a, b, c});
            mesh.triangles.push_back({a, c, d});
        }
    return mesh;
}

unsigned sheet_side(std::size_t budget) {
    return std::max(1u, static_cast<unsigned>(std::lround(std::sqrt(budget / 2.0))));
}

Mesh make_square(std::size_t budget) {
    const unsigned n = sheet_side(budget);
    return make_sheet(
        n, n, [](double, double) { return 0.0; },
        [](double x, double y) { return glm::dvec2(x + 1.0, y + 1.0) * 0.5; });
}

constexpr double kWaveAmplitude = 0.12;
double wave_height(double x) { return kWaveAmplitude * std::sin(2.0 * kPi * x); }
// Arc length of the wave from x = -1 to x (Simpson's rule, fine enough for float uvs).
double wave_arc_length(double x) {
    const int steps = 2048;
    const double h = (x + 1.0) / steps;
    const auto speed = [](double t) {
        const double slope = kWaveAmplitude * 2.0 * kPi * std::cos(2.0 * kPi * t);
        return std::sqrt(1.0 + slope * slope);
    };
    double sum = speed(-1.0) + speed(x);
    for (int k = 1; k < steps; ++k) sum += (k % 2 ? 4.0 : 2.0) * speed(-1.0 + k * h);
    return sum * h / 3.0;
}

Mesh make_wave(std::size_t budget) {
    const unsigned n = sheet_side(budget);
    return make_sheet(
        n, n, [](double x, double) { return wave_height(x); },
        [](double x, double y) { return glm::dvec2(wave_arc_length(x), y + 1.0) * 0.5; });
}

Mesh make_drape(std::size_t budget) {
    const unsigned n = sheet_side(budget);
    return make_sheet(
        n, n,
        [](double x, double y) { return 0.2 * std::sin(kPi * x) * std::sin(kPi * y); },
        [](double x, double y) { return glm::dvec2(x + 1.0, y + 1.0) * 0.5; });
}

struct Builtin {
    const char* name;
    Mesh (*make)(std::size_t);
    std::size_t default_budget = kDefaultFaceBudget;
    std::size_t min_budget = kMinFaceBudget;
};
const Builtin kBuiltins[] = {{"sphere", make_sphere},         {"torus", make_torus},
                             {"torus_knot", make_torus_knot}, {"hand", make_hand},
                             {"square", make_square, 2, 2},   {"wave", make_wave, 800, 2},
                             {"drape", make_drape, 12800, 2}};

const Builtin* find_builtin(const std::string& name) {
    for (const Builtin& b : kBuiltins)
        if (name == b.name) return &b;
    return nullptr;
}

std::size_t parse_face_budget(const std::string& spec, const std::string& text,
                              std::size_t min_budget) {
    const std::string usage = spec +
                              ": face budget must be a whole number like 30000 or 240k, "
                              "between " +
                              std::to_string(min_budget) + " and 20m";
    std::size_t value = 0;
    const char* end = text.data() + text.size();
    const auto [rest, error] = std::from_chars(text.data(), end, value);
    if (error != std::errc{} || text.empty()) throw MeshError(usage);
    std::size_t scale = 1;
    const std::string suffix(rest, end);
    if (suffix == "k" || suffix == "K")
        scale = 1000;
    else if (suffix == "m" || suffix == "M")
        scale = 1'000'000;
    else if (!suffix.empty())
        throw MeshError(usage);
    if (value > kMaxFaceBudget / scale) throw MeshError(usage);
    value *= scale;
    if (value < min_budget || value > kMaxFaceBudget) throw MeshError(usage);
    return value;
}

}  // namespace

std::vector<std::string> builtin_mesh_names() {
    std::vector<std::string> names;
    for (const Builtin& b : kBuiltins) names.emplace_back(b.name);
    return names;
}

bool is_builtin_mesh_spec(const std::string& spec) {
    return find_builtin(spec.substr(0, spec.find(':'))) != nullptr;
}

Mesh build_builtin_mesh(const std::string& spec) {
    const std::size_t colon = spec.find(':');
    const Builtin* builtin = find_builtin(spec.substr(0, colon));
    if (builtin == nullptr) {
        std::string names;
        for (const Builtin& b : kBuiltins)
            names += (names.empty() ? "" : ", ") + std::string(b.name);
        throw MeshError(spec + ": not a built-in mesh (" + names + ")");
    }
    const std::size_t budget =
        colon == std::string::npos
            ? builtin->default_budget
            : parse_face_budget(spec, spec.substr(colon + 1), builtin->min_budget);
    Mesh mesh = builtin->make(budget);
    mesh.name = spec;
    finalize_mesh(mesh);
    return mesh;
}

}  // namespace lucent
