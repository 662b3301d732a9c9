#include "scene.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <tuple>

namespace pathtrace {

using envmis::cross;
using envmis::dot;
using envmis::normalize;

// ---------------------------------------------------------------------------------------
// Materials

Material Material::plastic(std::string name, Rgb albedo, float roughness) {
    return {std::move(name), envmis::Bsdf::lambert(albedo), envmis::Bsdf::ggx(roughness, {1, 1, 1}), 0.2f};
}

envmis::BsdfValues<float> Material::values(Vec3 wo, Vec3 wi) const noexcept {
    const envmis::BsdfValues<float> b = base.values(wo, wi);
    if (!coat) return b;
    const envmis::BsdfValues<float> c = coat->values(wo, wi);
    const float w = coat_weight, v = 1 - coat_weight;
    return {v * b.pdf + w * c.pdf, v * b.r + w * c.r, v * b.g + w * c.g, v * b.b + w * c.b};
}

envmis::BsdfSample Material::sample(Vec3 wo, Vec2 u, float choice) const noexcept {
    if (!coat) return base.sample(wo, u);
    const envmis::BsdfSample s = (choice < coat_weight ? *coat : base).sample(wo, u);
    if (!(s.pdf > 0)) return {};
    const envmis::BsdfValues<float> v = values(wo, s.wi);
    return {s.wi, v.pdf, {v.r, v.g, v.b}};
}

size_t SceneDescription::triangles() const noexcept {
    size_t n = 0;
    for (const Mesh& m : meshes) n += m.triangles();
    return n;
}

// ---------------------------------------------------------------------------------------
// Procedural meshes

namespace {

Vec3 rotate_z(Vec3 p, float angle) {
    const float c = std::cos(angle), s = std::sin(angle);
    return {c * p.x - s * p.y, s * p.x + c * p.y, p.z};
}
Vec3 rotate_x(Vec3 p, float angle) {
    const float c = std::cos(angle), s = std::sin(angle);
    return {p.x, c * p.y - s * p.z, s * p.y + c * p.z};
}

// A (nu + 1) x (nv + 1) grid of points at(u, v), u and v in [0, 1], two triangles a
// quad, counter-clockwise about d at / du x d at / dv.
Mesh grid(uint32_t nu, uint32_t nv, uint32_t material, const std::function<Vec3(float, float)>& at) {
    Mesh m;
    m.material = material;
    for (uint32_t j = 0; j <= nv; ++j)
        for (uint32_t i = 0; i <= nu; ++i)
            m.positions.push_back(
                at(static_cast<float>(i) / static_cast<float>(nu), static_cast<float>(j) / static_cast<float>(nv)));
    for (uint32_t j = 0; j < nv; ++j)
        for (uint32_t i = 0; i < nu; ++i) {
            const uint32_t a = j * (nu + 1) + i, b = a + 1, c = a + nu + 2, d = a + nu + 1;
            m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
        }
    return m;
}

// Vertex normals: the area-weighted mean of the faces around each vertex, with vertices
// at the same position (a grid's seams) merged so that seams shade smoothly.
void smooth_normals(Mesh& m, float weld) {
    std::vector<Vec3> sum(m.positions.size());
    for (size_t t = 0; t < m.indices.size(); t += 3) {
        const Vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]], c = m.positions[m.indices[t + 2]];
        const Vec3 n = cross(b - a, c - a);
        for (int k = 0; k < 3; ++k) sum[m.indices[t + k]] = sum[m.indices[t + k]] + n;
    }
    // Weld by sorting vertices on a quantised position (O(n log n)).
    std::vector<uint32_t> order(m.positions.size());
    for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    auto key = [&](uint32_t i) {
        const Vec3 p = m.positions[i] * (1 / weld);
        return std::tuple{std::lround(p.x), std::lround(p.y), std::lround(p.z)};
    };
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
    m.normals.assign(m.positions.size(), {});
    for (size_t first = 0; first < order.size();) {
        size_t last = first;
        Vec3 n;
        while (last < order.size() && key(order[last]) == key(order[first])) n = n + sum[order[last++]];
        const float l = envmis::length(n);
        for (size_t k = first; k < last; ++k) m.normals[order[k]] = l > 0 ? n * (1 / l) : Vec3{0, 0, 1};
        first = last;
    }
}

Mesh quad(Vec3 corner, Vec3 edge_u, Vec3 edge_v, uint32_t material) {
    return grid(1, 1, material, [&](float u, float v) { return corner + edge_u * u + edge_v * v; });
}

void append(std::vector<Mesh>& meshes, Mesh m) { meshes.push_back(std::move(m)); }

}  // namespace

Mesh ground_quad(float half_size, uint32_t material) {
    return quad({-half_size, -half_size, 0}, {2 * half_size, 0, 0}, {0, 2 * half_size, 0}, material);
}

Mesh box(Vec3 centre, Vec3 half_extent, float turn_z, float tilt_x, uint32_t material) {
    Mesh m;
    m.material = material;
    const Vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const float half[3] = {half_extent.x, half_extent.y, half_extent.z};
    for (int a = 0; a < 3; ++a)
        for (float sign : {-1.0f, 1.0f}) {
            // Face normal n = sign axes[a], tangents with u x v = n.
            const int b = (a + 1) % 3, c = (a + 2) % 3;
            const Vec3 n = axes[a] * sign, u = axes[b] * sign, v = axes[c];
            const float hu = half[b], hv = half[c];
            const auto base = static_cast<uint32_t>(m.positions.size());
            for (auto [su, sv] : {std::pair{-1.0f, -1.0f}, {1.0f, -1.0f}, {1.0f, 1.0f}, {-1.0f, 1.0f}}) {
                const Vec3 local = n * half[a] + u * (su * hu) + v * (sv * hv);
                m.positions.push_back(centre + rotate_z(rotate_x(local, tilt_x), turn_z));
            }
            m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
        }
    return m;
}

Mesh uv_sphere(Vec3 centre, float radius, uint32_t segments, uint32_t material) {
    Mesh m = grid(2 * segments, segments, material, [&](float u, float v) {
        const float phi = 2 * envmis::kPiF * u, theta = envmis::kPiF * (1 - v);
        return centre +
               Vec3{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)} * radius;
    });
    smooth_normals(m, radius * 1e-4f);
    return m;
}

Mesh torus(Vec3 centre, float major, float minor, uint32_t segments, uint32_t material) {
    Mesh m = grid(2 * segments, segments, material, [&](float u, float v) {
        const float phi = 2 * envmis::kPiF * u, psi = 2 * envmis::kPiF * v;
        const float r = major + minor * std::cos(psi);
        return centre + Vec3{r * std::cos(phi), r * std::sin(phi), minor * std::sin(psi)};
    });
    smooth_normals(m, minor * 1e-4f);
    return m;
}

Mesh heightfield(Vec3 centre, float half_size, float height, uint32_t cells, uint32_t material) {
    Mesh m = grid(cells, cells, material, [&](float u, float v) {
        const float x = 2 * u - 1, y = 2 * v - 1;
        const float ridges = std::sin(7 * x + 2 * y) * std::cos(5 * y - x) * 0.35f;
        const float hill = std::exp(-3 * (x * x + y * y));
        return centre + Vec3{x * half_size, y * half_size, height * std::max(0.0f, hill + ridges * hill)};
    });
    smooth_normals(m, half_size * 1e-5f);
    return m;
}

Mesh torus_knot(Vec3 centre, float scale, uint32_t segments, uint32_t sides, uint32_t material) {
    // The (2, 3) knot's centre line, a tube around it in the curve's normal plane, with
    // bumps along the tube so that normals vary at every scale.
    auto curve = [](float t) {
        const float r = 2 + std::cos(3 * t);
        return Vec3{r * std::cos(2 * t), r * std::sin(2 * t), std::sin(3 * t)} * (1.0f / 3);
    };
    Mesh m = grid(segments, sides, material, [&](float u, float v) {
        const float t = 2 * envmis::kPiF * u, psi = 2 * envmis::kPiF * v;
        const Vec3 p = curve(t), ahead = curve(t + 1e-3f);
        const Vec3 tangent = normalize(ahead - p);
        const Vec3 side = normalize(cross(tangent, {0, 0, 1})), up = cross(side, tangent);
        const float radius = 0.12f * (1 + 0.25f * std::sin(40 * t) * std::sin(6 * psi));
        return centre + (p + (side * std::cos(psi) + up * std::sin(psi)) * radius) * scale;
    });
    smooth_normals(m, scale * 1e-5f);
    return m;
}

Mesh load_obj(const std::filesystem::path& path, uint32_t material) {
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path.string(), config) || reader.GetAttrib().vertices.empty())
        throw std::runtime_error(path.string() + ": not a readable OBJ file with vertices" +
                                 (reader.Error().empty() ? "" : ": " + reader.Error()));
    const tinyobj::attrib_t& attrib = reader.GetAttrib();
    Mesh m;
    m.material = material;
    bool normals = !attrib.normals.empty();
    const auto vertex_count = attrib.vertices.size() / 3;
    for (const tinyobj::shape_t& shape : reader.GetShapes())
        for (const tinyobj::index_t& i : shape.mesh.indices) {
            if (i.vertex_index < 0 || static_cast<size_t>(i.vertex_index) >= vertex_count)
                throw std::runtime_error(path.string() + ": a face names a vertex the file does not have");
            const auto v = static_cast<size_t>(i.vertex_index) * 3;
            m.positions.push_back({attrib.vertices[v], attrib.vertices[v + 1], attrib.vertices[v + 2]});
            normals = normals && i.normal_index >= 0 && static_cast<size_t>(i.normal_index) * 3 < attrib.normals.size();
            if (normals) {
                const auto n = static_cast<size_t>(i.normal_index) * 3;
                m.normals.push_back(normalize({attrib.normals[n], attrib.normals[n + 1], attrib.normals[n + 2]}));
            }
            m.indices.push_back(static_cast<uint32_t>(m.indices.size()));
        }
    if (m.indices.empty()) throw std::runtime_error(path.string() + ": no faces");
    if (!normals) m.normals.clear();
    return m;
}

// ---------------------------------------------------------------------------------------
// The scenes

namespace {

// Fits a mesh into a box of the given size standing on the ground at (x, y).
void stand(Mesh& m, float size, float x, float y) {
    Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
    for (const Vec3& p : m.positions) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    const float extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    const float s = extent > 0 ? size / extent : 1;
    const Vec3 offset{x - 0.5f * (lo.x + hi.x) * s, y - 0.5f * (lo.y + hi.y) * s, -lo.z * s};
    for (Vec3& p : m.positions) p = p * s + offset;
}

SceneDescription objects_scene() {
    SceneDescription s{"objects", {}, {}, {{0.5f, -9.5f, 4.0f}, {0, 0, 0.7f}, 38}};
    s.materials = {Material::single("ground", envmis::Bsdf::lambert({0.5f, 0.5f, 0.5f})),
                   Material::single("red", envmis::Bsdf::lambert({0.7f, 0.25f, 0.2f})),
                   Material::single("white", envmis::Bsdf::lambert({0.8f, 0.8f, 0.8f})),
                   Material::single("green", envmis::Bsdf::lambert({0.3f, 0.6f, 0.3f})),
                   Material::plastic("blue plastic", {0.2f, 0.3f, 0.7f}, 0.15f),
                   Material::single("phong", envmis::Bsdf::phong(50, {0.8f, 0.8f, 0.8f}))};
    append(s.meshes, ground_quad(60, 0));
    append(s.meshes, heightfield({0, 3.5f, 0}, 4, 1.6f, 128, 3));
    append(s.meshes, uv_sphere({-2.2f, 0, 0.8f}, 0.8f, 48, 1));
    append(s.meshes, uv_sphere({2.3f, 0.6f, 0.6f}, 0.6f, 48, 5));
    append(s.meshes, torus({0, -1.0f, 0.35f}, 0.8f, 0.35f, 48, 4));
    append(s.meshes, box({-0.6f, 1.4f, 0.9f}, {0.5f, 0.5f, 0.5f}, 0.5f, 0.6f, 2));
    append(s.meshes, box({1.2f, -2.4f, 0.4f}, {0.4f, 0.6f, 0.4f}, -0.4f, 0, 2));
    append(s.meshes, box({-3.2f, -1.8f, 0.5f}, {0.5f, 0.3f, 0.5f}, 0.9f, 0.9f, 1));
    return s;
}

SceneDescription materials_scene() {
    SceneDescription s{"materials", {}, {}, {{0, -9, 4.6f}, {0, 0, 0.3f}, 34}};
    s.materials = {Material::single("ground", envmis::Bsdf::lambert({0.5f, 0.5f, 0.5f})),
                   Material::single("lambert", envmis::Bsdf::lambert({0.8f, 0.8f, 0.8f})),
                   Material::single("phong:20", envmis::Bsdf::phong(20, {0.8f, 0.8f, 0.8f})),
                   Material::single("phong:200", envmis::Bsdf::phong(200, {0.8f, 0.8f, 0.8f})),
                   Material::single("ggx:0.1", envmis::Bsdf::ggx(0.1f)),
                   Material::single("ggx:0.3", envmis::Bsdf::ggx(0.3f)),
                   Material::plastic("plastic", {0.7f, 0.2f, 0.2f}, 0.1f)};
    append(s.meshes, ground_quad(60, 0));
    for (uint32_t k = 1; k < s.materials.size(); ++k) {
        const float x = (static_cast<float>(k) - 3.5f) * 1.35f;
        append(s.meshes, uv_sphere({x, 0.9f, 0.55f}, 0.55f, 48, k));
        append(s.meshes, box({x, -1.2f, 0.35f}, {0.35f, 0.35f, 0.35f}, 0.6f, 0, k));
    }
    return s;
}

// A room 8 x 8 x 3.5 with a window 5 wide and 2 tall in its -y wall: walls, floor and
// ceiling are quads (two-sided), so the sky reaches inside only through the window.
SceneDescription interior_scene() {
    SceneDescription s{"interior", {}, {}, {{3.2f, 3.2f, 2.4f}, {-0.5f, -1.5f, 0.7f}, 60}};
    s.materials = {Material::single("walls", envmis::Bsdf::lambert({0.7f, 0.7f, 0.7f})),
                   Material::single("floor", envmis::Bsdf::phong(20, {0.5f, 0.4f, 0.3f})),
                   Material::single("red", envmis::Bsdf::lambert({0.7f, 0.25f, 0.2f})),
                   Material::plastic("blue plastic", {0.2f, 0.3f, 0.7f}, 0.15f)};
    const float h = 4, z = 3.5f;
    append(s.meshes, quad({-h, -h, 0}, {2 * h, 0, 0}, {0, 2 * h, 0}, 1));  // floor
    append(s.meshes, quad({-h, -h, z}, {0, 2 * h, 0}, {2 * h, 0, 0}, 0));  // ceiling
    append(s.meshes, quad({-h, h, 0}, {2 * h, 0, 0}, {0, 0, z}, 0));       // +y wall
    append(s.meshes, quad({-h, -h, 0}, {0, 2 * h, 0}, {0, 0, z}, 0));      // -x wall
    append(s.meshes, quad({h, -h, 0}, {0, 0, z}, {0, 2 * h, 0}, 0));       // +x wall
    // The -y wall around its window (x in [-2.5, 2.5], z in [0.8, 2.8]).
    append(s.meshes, quad({-h, -h, 0}, {0, 0, 0.8f}, {2 * h, 0, 0}, 0));
    append(s.meshes, quad({-h, -h, 2.8f}, {0, 0, z - 2.8f}, {2 * h, 0, 0}, 0));
    append(s.meshes, quad({-h, -h, 0.8f}, {0, 0, 2}, {h - 2.5f, 0, 0}, 0));
    append(s.meshes, quad({2.5f, -h, 0.8f}, {0, 0, 2}, {h - 2.5f, 0, 0}, 0));
    append(s.meshes, uv_sphere({-1.5f, -1.0f, 0.7f}, 0.7f, 48, 2));
    append(s.meshes, box({0.8f, -0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}, 0.7f, 0, 3));
    append(s.meshes, torus({-0.2f, 1.5f, 0.35f}, 0.7f, 0.3f, 48, 2));
    return s;
}

SceneDescription mesh_scene(const std::optional<std::filesystem::path>& obj) {
    SceneDescription s{"mesh", {}, {}, {{0, -6.5f, 2.6f}, {0, 0, 0.9f}, 34}};
    s.materials = {Material::single("ground", envmis::Bsdf::lambert({0.5f, 0.5f, 0.5f})),
                   Material::plastic("plastic", {0.75f, 0.55f, 0.25f}, 0.2f)};
    append(s.meshes, ground_quad(60, 0));
    Mesh m = obj ? load_obj(*obj, 1) : torus_knot({0, 0, 0}, 1, 1024, 64, 1);
    stand(m, 2.6f, 0, 0);
    append(s.meshes, std::move(m));
    return s;
}

}  // namespace

SceneDescription make_scene(std::string_view name, const std::optional<std::filesystem::path>& obj) {
    if (name == "objects") return objects_scene();
    if (name == "materials") return materials_scene();
    if (name == "interior") return interior_scene();
    if (name == "mesh") return mesh_scene(obj);
    throw std::invalid_argument("unknown scene '" + std::string(name) + "' (expected " + std::string(kSceneNames) +
                                ")");
}

// ---------------------------------------------------------------------------------------
// Ray queries

RayScene::RayScene(const SceneDescription& scene) : description_(&scene) {
    device_ = rtcNewDevice(nullptr);
    if (!device_) throw std::runtime_error("Embree: cannot create a device");
    scene_ = rtcNewScene(device_);
    float extent = 1;
    for (const Mesh& m : scene.meshes) {
        if (!m.normals.empty() && m.normals.size() != m.positions.size())
            throw std::invalid_argument("a mesh has " + std::to_string(m.normals.size()) + " normals for " +
                                        std::to_string(m.positions.size()) + " vertices");
        RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                              3 * sizeof(float), m.positions.size()));
        auto* i = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(uint32_t), m.triangles()));
        for (const Vec3& p : m.positions) {
            *v++ = p.x, *v++ = p.y, *v++ = p.z;
            extent = std::max({extent, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
        }
        std::copy(m.indices.begin(), m.indices.end(), i);
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene_, g);  // IDs in order: the mesh's index
        rtcReleaseGeometry(g);
    }
    rtcCommitScene(scene_);
    epsilon_ = 2e-5f * extent;
}

RayScene::~RayScene() {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
}

namespace {
RTCRay make_ray(Vec3 origin, Vec3 direction) {
    RTCRay r{};
    r.org_x = origin.x, r.org_y = origin.y, r.org_z = origin.z;
    r.dir_x = direction.x, r.dir_y = direction.y, r.dir_z = direction.z;
    r.tnear = 0, r.tfar = INFINITY, r.mask = ~0u;
    return r;
}
}  // namespace

std::optional<Hit> RayScene::intersect(Vec3 origin, Vec3 direction) const noexcept {
    RTCRayHit rh{};
    rh.ray = make_ray(origin, direction);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    rtcIntersect1(scene_, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
    const Mesh& m = description_->meshes[rh.hit.geomID];
    Vec3 ng = normalize({rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z});
    if (dot(ng, direction) > 0) ng = ng * -1.0f;
    Vec3 ns = ng;
    if (!m.normals.empty()) {
        const uint32_t* t = &m.indices[size_t{rh.hit.primID} * 3];
        const float u = rh.hit.u, v = rh.hit.v;
        ns = normalize(m.normals[t[0]] * (1 - u - v) + m.normals[t[1]] * u + m.normals[t[2]] * v);
        if (dot(ns, ng) < 0) ns = ns * -1.0f;
    }
    return Hit{origin + direction * rh.ray.tfar, ng, ns, m.material};
}

bool RayScene::occluded(Vec3 origin, Vec3 direction) const noexcept {
    RTCRay r = make_ray(origin, direction);
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    rtcOccluded1(scene_, &context, &r);
    return r.tfar < 0;  // Embree sets tfar to -inf on a hit
}

}  // namespace pathtrace
