// `embree`: Embree 3's own BVH over the same scene, the reference and the peer that rtcost's
// hierarchies are checked and timed against. Triangles and spheres use Embree's native
// primitives; polygons and cones are user geometry calling rtcost's exact intersectors. Embree's
// internal operations cannot be counted, so its counters hold only the rays.
#include <atomic>
#include <deque>
#include <embree3/rtcore.h>
#include <fmt/format.h>

#include "rtcost/error.hpp"
#include "rtcost/hierarchy.hpp"

namespace rtcost {
namespace {

class EmbreeHierarchy final : public Hierarchy {
public:
    /// Embree's internal operations are not visible: it is timed, not counted.
    bool counted() const override { return false; }

    EmbreeHierarchy(const Scene& scene, const Params& p) : Hierarchy(scene) {
        long long threads = p.integer("threads");
        std::string config = threads > 0 ? "threads=" + std::to_string(threads) : "";
        device_ = rtcNewDevice(config.c_str());
        if (!device_) throw InputError("embree", 0, "cannot create an Embree device");
        rtcSetDeviceMemoryMonitorFunction(device_, &EmbreeHierarchy::monitor, this);
        rs_ = rtcNewScene(device_);
        rtcSetSceneFlags(rs_, p.flag("robust") ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
        const std::string& q = p.str("quality");
        rtcSetSceneBuildQuality(rs_, q == "low" ? RTC_BUILD_QUALITY_LOW
                                     : q == "high" ? RTC_BUILD_QUALITY_HIGH
                                                   : RTC_BUILD_QUALITY_MEDIUM);
        std::vector<std::uint32_t> tris, spheres, users;
        for (std::uint32_t id = 0; id < scene.size(); ++id) {
            switch (scene.kind(id)) {
                case PrimKind::Triangle: tris.push_back(id); break;
                case PrimKind::Sphere: spheres.push_back(id); break;
                default: users.push_back(id); break;
            }
        }
        if (!tris.empty()) {
            RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
            auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                  3 * sizeof(float), 3 * tris.size()));
            auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                       3 * sizeof(unsigned), tris.size()));
            for (std::size_t i = 0; i < tris.size(); ++i) {
                const Triangle& t = scene.triangles[scene.prims[tris[i]].index];
                const Vec3* vs[3] = {&t.v0, &t.v1, &t.v2};
                for (int k = 0; k < 3; ++k) {
                    v[9 * i + 3 * k + 0] = vs[k]->x;
                    v[9 * i + 3 * k + 1] = vs[k]->y;
                    v[9 * i + 3 * k + 2] = vs[k]->z;
                    idx[3 * i + k] = static_cast<unsigned>(3 * i + k);
                }
            }
            attach(g, std::move(tris));
        }
        if (!spheres.empty()) {
            RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_SPHERE_POINT);
            auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                                  4 * sizeof(float), spheres.size()));
            for (std::size_t i = 0; i < spheres.size(); ++i) {
                const Sphere& s = scene.spheres[scene.prims[spheres[i]].index];
                v[4 * i + 0] = s.center.x;
                v[4 * i + 1] = s.center.y;
                v[4 * i + 2] = s.center.z;
                v[4 * i + 3] = s.radius;
            }
            attach(g, std::move(spheres));
        }
        if (!users.empty()) {
            RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
            rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(users.size()));
            rtcSetGeometryBoundsFunction(g, &EmbreeHierarchy::user_bounds, nullptr);
            rtcSetGeometryIntersectFunction(g, &EmbreeHierarchy::user_intersect);
            rtcSetGeometryOccludedFunction(g, &EmbreeHierarchy::user_occluded);
            attach(g, std::move(users));
        }
        rtcCommitScene(rs_);
        if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw InputError("embree", 0, "Embree failed to build the scene");
    }

    ~EmbreeHierarchy() override {
        rtcReleaseScene(rs_);
        rtcReleaseDevice(device_);
    }

    std::string_view name() const override { return "embree"; }

    void closest(const Ray& ray, Hit& hit) const override {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRayHit rh = make(ray);
        rtcIntersect1(rs_, &ctx, &rh);
        if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
            hit.t = rh.ray.tfar;
            hit.prim = static_cast<std::int32_t>(geoms_[rh.hit.geomID].ids[rh.hit.primID]);
        }
    }
    void closest(const Ray& ray, Hit& hit, RayCounters& c) const override {
        ++c.rays;
        closest(ray, hit);
    }
    bool any(const Ray& ray, Hit& hit) const override {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRayHit rh = make(ray);
        rtcOccluded1(rs_, &ctx, &rh.ray);
        if (rh.ray.tfar == -kInf) {
            hit.prim = 0;  // Embree does not say which primitive occludes
            return true;
        }
        return false;
    }
    bool any(const Ray& ray, Hit& hit, RayCounters& c) const override {
        ++c.rays;
        return any(ray, hit);
    }

    // Embree always terminates at the closest hit; all-hits is not a mode it has.
    void all(const Ray& ray, Hit& hit) const override { closest(ray, hit); }
    void all(const Ray& ray, Hit& hit, RayCounters& c) const override { closest(ray, hit, c); }

protected:
    StructureStats compute_structure() const override {
        StructureStats s;
        s.references = scene_->size();
        s.bytes = static_cast<std::uint64_t>(std::max<std::int64_t>(0, bytes_.load()));
        return s;
    }

private:
    struct Geom {
        std::vector<std::uint32_t> ids;  // Embree primID -> rtcost primitive id
        const Scene* scene;
    };

    void attach(RTCGeometry g, std::vector<std::uint32_t> ids) {
        geoms_.push_back(Geom{std::move(ids), scene_});
        rtcSetGeometryUserData(g, &geoms_.back());
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(rs_, g, static_cast<unsigned>(geoms_.size() - 1));
        rtcReleaseGeometry(g);
    }

    static RTCRayHit make(const Ray& r) {
        RTCRayHit rh{};
        rh.ray.org_x = r.o.x; rh.ray.org_y = r.o.y; rh.ray.org_z = r.o.z;
        rh.ray.dir_x = r.d.x; rh.ray.dir_y = r.d.y; rh.ray.dir_z = r.d.z;
        rh.ray.tnear = r.tmin;
        rh.ray.tfar = r.tmax;
        rh.ray.mask = ~0u;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
        return rh;
    }

    static bool monitor(void* self, ssize_t bytes, bool) {
        static_cast<EmbreeHierarchy*>(self)->bytes_ += bytes;
        return true;
    }

    static void user_bounds(const RTCBoundsFunctionArguments* a) {
        const Geom& g = *static_cast<const Geom*>(a->geometryUserPtr);
        Box3 b = g.scene->prim_bounds(g.ids[a->primID]);
        *a->bounds_o = RTCBounds{b.lo.x, b.lo.y, b.lo.z, 0, b.hi.x, b.hi.y, b.hi.z, 0};
    }

    static void user_intersect(const RTCIntersectFunctionNArguments* a) {
        const Geom& g = *static_cast<const Geom*>(a->geometryUserPtr);
        auto* rh = reinterpret_cast<RTCRayHit*>(a->rayhit);
        Ray r{{rh->ray.org_x, rh->ray.org_y, rh->ray.org_z}, {rh->ray.dir_x, rh->ray.dir_y, rh->ray.dir_z},
              rh->ray.tnear, rh->ray.tfar};
        float t;
        if (g.scene->intersect(g.ids[a->primID], r, t)) {
            rh->ray.tfar = t;
            rh->hit.geomID = a->geomID;
            rh->hit.primID = a->primID;
            rh->hit.instID[0] = a->context->instID[0];
        }
    }

    static void user_occluded(const RTCOccludedFunctionNArguments* a) {
        const Geom& g = *static_cast<const Geom*>(a->geometryUserPtr);
        auto* ray = reinterpret_cast<RTCRay*>(a->ray);
        Ray r{{ray->org_x, ray->org_y, ray->org_z}, {ray->dir_x, ray->dir_y, ray->dir_z}, ray->tnear, ray->tfar};
        float t;
        if (g.scene->intersect(g.ids[a->primID], r, t)) ray->tfar = -kInf;
    }

    RTCDevice device_ = nullptr;
    RTCScene rs_ = nullptr;
    std::deque<Geom> geoms_;  // stable addresses: Embree keeps pointers to them
    std::atomic<std::int64_t> bytes_{0};
};

const Registration reg{{"embree",
                        "Embree 3 BVH (reference peer; its internal operations are not counted)",
                        {ParamSpec::choice("quality", "medium", {"low", "medium", "high"}, "Embree build quality"),
                         ParamSpec::flag("robust", "1", "RTC_SCENE_FLAG_ROBUST: no accuracy-reducing shortcuts"),
                         ParamSpec::integer("threads", "0", 0, 1024, "Embree's build threads (0: all cores)")},
                        [](const Scene& s, const Params& p) { return std::make_unique<EmbreeHierarchy>(s, p); }}};

}  // namespace
}  // namespace rtcost
