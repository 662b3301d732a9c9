// The path tracer's scenes: triangle meshes with one material each, a camera, and the
// ray queries over them (Embree 3). World frame z up, as `envmis precompute` assumes by
// default (--axes z-up).
//
// Scenes are generated here (procedural meshes at full triangle count) or read from
// Wavefront OBJ files (tinyobjloader), so that the repository holds no binary meshes:
//   objects    normals facing every way on a ground: spheres, tilted boxes, a torus,
//              a heightfield, mostly diffuse (where a normal-aware table should gain most)
//   materials  a sphere and a box of every material in two rows on a ground
//   interior   a closed room lit through one opening in a wall: most of the sky occluded
//   mesh       a displaced torus knot of 131 072 triangles (or --obj FILE) on a ground
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "envmis/math/math.h"
#include "envmis/study/shading/bsdf.h"

namespace pathtrace {

using envmis::Rgb;
using envmis::Vec2;
using envmis::Vec3;

// A surface's scattering: one analytic lobe (Lambert, Phong, GGX) or a two-lobe plastic,
// a diffuse base under a GGX coat, mixed with a fixed weight (energy conserving, since
// each lobe reflects at most what arrives). `values` and `sample` work in the local
// shading frame (z = normal) and return f cos(theta_i) with the solid-angle pdf of
// sampling as `sample` does: the mixture's, so MIS weights see the true density.
struct Material {
    std::string name;
    envmis::Bsdf base;
    std::optional<envmis::Bsdf> coat;  // plastic's GGX lobe
    float coat_weight = 0;             // probability of sampling the coat; its share of f

    static Material single(std::string name, envmis::Bsdf bsdf) { return {std::move(name), bsdf, {}, 0}; }
    static Material plastic(std::string name, Rgb albedo, float roughness);

    envmis::BsdfValues<float> values(Vec3 wo, Vec3 wi) const noexcept;
    envmis::BsdfSample sample(Vec3 wo, Vec2 u, float choice) const noexcept;
    // The sharpness that picks the lobe class of a normal-aware table (BinnedEnvMap::lobe_class):
    // the base's (a plastic's light is mostly its diffuse base's).
    float phong_exponent() const noexcept { return base.phong_exponent(); }
};

struct Mesh {
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;      // per vertex (smooth shading), or empty (flat)
    std::vector<uint32_t> indices;  // three per triangle
    uint32_t material = 0;

    size_t triangles() const noexcept { return indices.size() / 3; }
};

struct Camera {
    Vec3 from, at;
    float vertical_fov_degrees = 40;
};

struct SceneDescription {
    std::string name;
    std::vector<Material> materials;
    std::vector<Mesh> meshes;
    Camera camera;

    size_t triangles() const noexcept;
};

// The scenes above by name; `obj` replaces the mesh scene's knot (read with
// tinyobjloader, scaled to fit a 2-unit box on the ground). Throws std::invalid_argument
// on an unknown name and std::runtime_error on an unreadable OBJ file.
SceneDescription make_scene(std::string_view name, const std::optional<std::filesystem::path>& obj = {});
inline constexpr std::string_view kSceneNames = "objects, materials, interior, mesh";

// Procedural meshes (counter-clockwise seen from outside, so geometric normals face out).
Mesh ground_quad(float half_size, uint32_t material);
Mesh box(Vec3 centre, Vec3 half_extent, float turn_z, float tilt_x, uint32_t material);
Mesh uv_sphere(Vec3 centre, float radius, uint32_t segments, uint32_t material);
Mesh torus(Vec3 centre, float major, float minor, uint32_t segments, uint32_t material);
Mesh heightfield(Vec3 centre, float half_size, float height, uint32_t cells, uint32_t material);
Mesh torus_knot(Vec3 centre, float scale, uint32_t segments, uint32_t sides, uint32_t material);
// An OBJ file's triangles (faces triangulated), vertex normals where it has them.
Mesh load_obj(const std::filesystem::path& path, uint32_t material);

// A surface point found by a ray: position, geometric normal and shading normal, both
// facing the side the ray came from, and the material.
struct Hit {
    Vec3 point, geometric_normal, shading_normal;
    uint32_t material = 0;
};

// The meshes in an Embree BVH; queries from any number of threads at once.
class RayScene {
public:
    explicit RayScene(const SceneDescription& scene);
    ~RayScene();
    RayScene(const RayScene&) = delete;
    RayScene& operator=(const RayScene&) = delete;

    std::optional<Hit> intersect(Vec3 origin, Vec3 direction) const noexcept;
    // True if anything lies along the ray within (0, infinity): the sky is not seen.
    bool occluded(Vec3 origin, Vec3 direction) const noexcept;
    // How far to lift a ray's origin off the surface it leaves (scene-scaled).
    float epsilon() const noexcept { return epsilon_; }

private:
    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    const SceneDescription* description_;
    float epsilon_ = 1e-4f;
};

}  // namespace pathtrace
