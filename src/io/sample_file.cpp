// The ray sample file (README, "Sample files"): fixed-size little-endian records, so no
// serialisation library is needed.
#include <bit>
#include <cstring>
#include <fstream>
#include <iterator>

#include "rtcost/io.hpp"
#include "rtcost/sample.hpp"

static_assert(std::endian::native == std::endian::little, "sample files are little-endian");

namespace rtcost {
namespace {

constexpr char kMagic[8] = {'R', 'T', 'C', 'S', 'A', 'M', 'P', 'L'};
// Version 2 added the scene's fingerprint after the counts; version 1 files are still read.
// Version 3 has version 2's layout: it marks files written since an NFF polygon of three vertices
// is stored as a triangle, which changed such a scene's fingerprint (evaluate says so when a
// version-2 file's fingerprint does not match).
constexpr std::uint32_t kVersion = 3;
constexpr std::size_t kHeader = 8 + 4 + 4 + 5 * 8 + 4;  // magic, version, reserved, 4 counts, fingerprint, text length
constexpr std::size_t kRayRecord = 8 * 4 + 1 + 1 + 2 + 4;
constexpr std::size_t kCrossingRecord = 8;

template <class T>
void put(std::string& out, const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

}  // namespace

void write_sample(const std::string& path, const RaySample& s) {
    std::string out;
    out.reserve(kHeader + s.distribution.size() + s.size() * kRayRecord + s.crossings.size() * kCrossingRecord);
    out.append(kMagic, 8);
    put(out, kVersion);
    put(out, std::uint32_t{0});
    put(out, std::uint64_t{s.seed});
    put(out, std::uint64_t{s.population});
    put(out, std::uint64_t{s.size()});
    put(out, std::uint64_t{s.crossings.size()});
    put(out, std::uint64_t{s.scene});
    put(out, static_cast<std::uint32_t>(s.distribution.size()));
    out += s.distribution;
    for (std::size_t i = 0; i < s.size(); ++i) {
        const Ray& r = s.rays.rays[i];
        const float f[8] = {r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, r.tmin, r.tmax};
        out.append(reinterpret_cast<const char*>(f), sizeof f);
        put(out, static_cast<std::uint8_t>(s.rays.kinds[i]));
        put(out, static_cast<std::uint8_t>(s.queries[i]));
        put(out, static_cast<std::uint16_t>(s.first[i + 1] - s.first[i]));
        put(out, s.t_end[i]);
    }
    for (const Crossing& c : s.crossings) {
        put(out, c.prim);
        put(out, c.t);
    }
    write_file_atomic(path, out);
}

RaySample read_sample(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, 0, "no such file");
    const std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::size_t at = 0;
    auto need = [&](std::size_t n, const char* what) {
        if (b.size() - at < n) throw InputError(path, 0, std::string("truncated sample file (") + what + ")");
    };
    auto get = [&]<class T>(T& v, const char* what) {
        need(sizeof(T), what);
        std::memcpy(&v, b.data() + at, sizeof(T));
        at += sizeof(T);
    };
    need(8, "header");
    if (std::memcmp(b.data(), kMagic, 8) != 0) throw InputError(path, 0, "not a sample file (written by rtcost sample)");
    at = 8;
    std::uint32_t version = 0, reserved = 0, text = 0;
    std::uint64_t seed = 0, population = 0, rays = 0, crossings = 0, scene = 0;
    get(version, "header");
    if (version < 1 || version > kVersion)
        throw InputError(path, 0, "sample file version " + std::to_string(version) + " (this rtcost reads 1 to 3)");
    get(reserved, "header");
    get(seed, "header");
    get(population, "header");
    get(rays, "header");
    get(crossings, "header");
    if (version >= 2) get(scene, "header");
    get(text, "header");
    // The counts must fit the file before anything is allocated for them.
    const std::size_t left = b.size() - at;
    if (text > left || rays > left / kRayRecord || crossings > left / kCrossingRecord ||
        text + rays * kRayRecord + crossings * kCrossingRecord != left)
        throw InputError(path, 0, "the counts in the header do not match the file's size (truncated?)");
    RaySample s;
    s.seed = seed;
    s.population = population;
    s.scene = scene;
    s.file_version = version;
    s.path = path;
    s.distribution.assign(b.data() + at, text);
    at += text;
    s.rays.described = s.distribution + " (sample)";
    std::uint64_t total = 0;
    for (std::uint64_t i = 0; i < rays; ++i) {
        float f[8];
        std::memcpy(f, b.data() + at, sizeof f);
        at += sizeof f;
        std::uint8_t kind = 0, query = 0;
        std::uint16_t n = 0;
        float t_end = 0;
        get(kind, "ray");
        get(query, "ray");
        get(n, "ray");
        get(t_end, "ray");
        Ray r;
        r.o = {f[0], f[1], f[2]};
        r.d = {f[3], f[4], f[5]};
        r.tmin = f[6];
        r.tmax = f[7];
        const std::string where = "ray " + std::to_string(i) + ": ";
        // The rules of a ray file's records (a negative tmin, a far origin, ...).
        if (const std::string what = ray_problem(r); !what.empty()) throw InputError(path, 0, where + what);
        if (kind >= kRayKinds || query > 2) throw InputError(path, 0, where + "unknown kind or query");
        if (std::isnan(t_end) || t_end < r.tmin || t_end > r.tmax) throw InputError(path, 0, where + "end outside [tmin, tmax]");
        s.rays.rays.push_back(r);
        s.rays.kinds.push_back(static_cast<RayKind>(kind));
        s.queries.push_back(static_cast<Query>(query));
        s.t_end.push_back(t_end);
        s.first.push_back(static_cast<std::uint32_t>(total));
        total += n;
    }
    s.first.push_back(static_cast<std::uint32_t>(total));
    if (total != crossings) throw InputError(path, 0, "the rays' crossing counts do not add up to the header's");
    s.crossings.resize(crossings);
    for (Crossing& c : s.crossings) {
        get(c.prim, "crossing");
        get(c.t, "crossing");
        if (!(c.t >= 0)) throw InputError(path, 0, "a crossing's t is negative or NaN");
    }
    return s;
}

}  // namespace rtcost
