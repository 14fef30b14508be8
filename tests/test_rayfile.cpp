// Binary ray and hit files: exact layout, round trips, and rejection of bad files.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "rtcost/io.hpp"

namespace fs = std::filesystem;
using namespace rtcost;

namespace {

fs::path tmp(const std::string& name) { return fs::temp_directory_path() / ("rtcost_rf_" + std::to_string(::getpid()) + name); }

TEST(RayFile, LayoutIsEightLittleEndianFloats) {
    std::vector<Ray> rays = {{{1, 2, 3}, {4, 5, 6}, 0.5f, kInf}};
    write_rays(tmp("a").string(), rays);
    std::ifstream in(tmp("a"), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_EQ(bytes.size(), 32u);
    float f[8];
    std::memcpy(f, bytes.data(), 32);
    EXPECT_EQ(f[0], 1.0f);
    EXPECT_EQ(f[5], 6.0f);
    EXPECT_EQ(f[6], 0.5f);
    EXPECT_EQ(f[7], kInf);
    EXPECT_EQ(static_cast<unsigned char>(bytes[3]), 0x3f);  // 1.0f = 0x3f800000, little-endian
    auto back = read_rays(tmp("a").string());
    ASSERT_EQ(back.size(), 1u);
    EXPECT_EQ(back[0].o, rays[0].o);
    EXPECT_EQ(back[0].tmax, kInf);
}

TEST(HitFile, LayoutIsIdThenT) {
    std::vector<Hit> hits(2);
    hits[0].prim = 7;
    hits[0].t = 2.5f;
    write_hits(tmp("h").string(), hits);
    EXPECT_EQ(fs::file_size(tmp("h")), 16u);
    auto back = read_hits(tmp("h").string());
    EXPECT_EQ(back[0].prim, 7);
    EXPECT_EQ(back[0].t, 2.5f);
    EXPECT_EQ(back[1].prim, -1);
    EXPECT_EQ(back[1].t, kInf);
}

TEST(RayFile, BadFilesAreRejected) {
    auto expect_error = [](const std::string& bytes, const std::string& needle) {
        fs::path p = tmp("bad");
        std::ofstream(p, std::ios::binary) << bytes;
        try {
            read_rays(p.string());
            ADD_FAILURE() << "accepted: " << needle;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos);
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
        }
    };
    expect_error(std::string(31, '\0'), "not a multiple of 32");
    expect_error(std::string(32, '\0'), "direction is zero");
    float f[8] = {0, 0, 0, 1, 0, 0, 2, 1};
    expect_error(std::string(reinterpret_cast<char*>(f), 32), "tmin > tmax");
    f[6] = 0;
    f[1] = kInf;
    expect_error(std::string(reinterpret_cast<char*>(f), 32), "origin is not finite");
    EXPECT_THROW(read_rays("/no/such/file.rays"), InputError);
}

TEST(RayFile, EmptyFileIsRefused) {
    // Nothing to trace is bad input, as an empty scene is: named, not taken for zero rays.
    std::ofstream(tmp("e"), std::ios::binary);
    try {
        read_rays(tmp("e").string());
        FAIL() << "an empty ray file was read";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("empty: no rays in it"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(tmp("e").string()), std::string::npos) << e.what();
    }
}

TEST(AtomicWrite, FailureLeavesNothingBehind) {
    EXPECT_THROW(write_hits("/no/such/dir/out.hits", std::vector<Hit>(3)), InputError);
    EXPECT_FALSE(fs::exists("/no/such/dir/out.hits"));
}

}  // namespace
