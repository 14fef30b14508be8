// Typed build parameters: every registered hierarchy declares what each of its parameters takes,
// its defaults are among those values, values outside them are refused before a build starts,
// and `rtcost list` shows the declaration. A new hierarchy is checked without touching this file.
#include <nlohmann/json.hpp>

#include "rtcost/error.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

// The parameters whose values the builder checks itself: a resolution formula or AxBxC, a
// distribution name, an image size, a file.
bool free_text(const std::string& name) { return name == "res" || name == "rays" || name == "size" || name == "costs"; }

std::string message(const std::vector<ParamSpec>& specs, const std::string& assignment) {
    try {
        Params p(specs, {assignment});
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(Params, EveryParameterIsTypedAndItsDefaultIsOneOfItsValues) {
    std::size_t checked = 0;
    for (const HierarchyInfo* info : hierarchies()) {
        for (const ParamSpec& p : info->params) {
            const std::string what = info->name + " " + p.name;
            EXPECT_EQ(p.kind == ParamKind::Text, free_text(p.name)) << what << ": " << p.domain();
            EXPECT_EQ(p.problem(p.default_value), "") << what << " default " << p.default_value;
            if (p.kind == ParamKind::Integer || p.kind == ParamKind::Real) {
                EXPECT_LE(p.lo, p.hi) << what;
            }
            if (p.kind == ParamKind::Choice) {
                EXPECT_GE(p.words.size(), 2u) << what;
            }
            EXPECT_FALSE(p.help.empty()) << what;
            ++checked;
        }
        EXPECT_NO_THROW(Params(info->params, {})) << info->name;
    }
    EXPECT_GE(checked, 60u);
}

TEST(Params, ValuesOutsideTheDeclarationAreRefusedNamingIt) {
    std::size_t refused = 0;
    for (const HierarchyInfo* info : hierarchies()) {
        for (const ParamSpec& p : info->params) {
            const std::string what = info->name + " " + p.name;
            std::vector<std::string> bad;
            if (p.kind == ParamKind::Integer) {
                bad = {p.name + "=" + std::to_string(static_cast<long long>(p.hi) + 1), p.name + "=1.5", p.name + "=x"};
                if (p.lo > -1e18) bad.push_back(p.name + "=" + std::to_string(static_cast<long long>(p.lo) - 1));
            } else if (p.kind == ParamKind::Real) {
                bad = {p.name + "=" + std::to_string(p.hi * 2 + 1), p.name + "=nan", p.name + "=inf", p.name + "=x"};
            } else if (p.kind == ParamKind::Flag) {
                bad = {p.name + "=2", p.name + "=maybe"};
            } else if (p.kind == ParamKind::Choice) {
                bad = {p.name + "=" + p.words.front() + "x"};
            }
            for (const std::string& b : bad) {
                const std::string m = message(info->params, b);
                EXPECT_NE(m.find(b + ":"), std::string::npos) << what << ": '" << b << "' gave '" << m << "'";
                ++refused;
            }
        }
    }
    EXPECT_GE(refused, 150u);
}

TEST(Params, AccessorsReadTheDeclaredRangeAndWords) {
    const std::vector<ParamSpec> specs = {ParamSpec::integer("depth", "auto", 0, 64, "a depth", {"auto"}),
                                          ParamSpec::real("ratio", "0.5", 0, 1, "a ratio"),
                                          ParamSpec::flag("on", "yes", "a switch"),
                                          ParamSpec::choice("mode", "a", {"a", "b"}, "a mode")};
    EXPECT_EQ(specs[0].domain(), "integer in [0, 64], or auto");
    EXPECT_EQ(specs[1].domain(), "number in [0, 1]");
    EXPECT_EQ(specs[3].domain(), "one of a, b");
    const Params d(specs, {});
    EXPECT_TRUE(d.is("depth", "auto"));
    EXPECT_THROW(d.integer("depth"), InputError);  // a word, not a number
    EXPECT_EQ(d.real("ratio"), 0.5);
    EXPECT_TRUE(d.flag("on"));
    const Params p(specs, {"depth=64", "ratio=1", "on=0", "mode=b"});
    EXPECT_EQ(p.integer("depth"), 64);
    EXPECT_EQ(p.real("ratio"), 1.0);
    EXPECT_FALSE(p.flag("on"));
    EXPECT_TRUE(p.is("mode", "b"));
    EXPECT_EQ(message(specs, "depth=65"), "--set: depth=65: must be in [0, 64]");
    EXPECT_EQ(message(specs, "mode=c"), "--set: mode=c: expected one of a, b");
    // A declaration whose own default it does not take fails the first build, not a later run.
    EXPECT_THROW(Params({ParamSpec::integer("n", "0", 1, 8, "n")}, {}), InputError);
}

TEST(Params, ListShowsEachDeclarationAndBuildRefusesOutsideIt) {
    const CliRun list = run_cli("list --json", 60);
    ASSERT_EQ(list.code, 0) << list.err;
    const auto j = nlohmann::json::parse(list.out);
    bool seen = false;
    for (const auto& h : j["hierarchies"]) {
        if (h["name"] != "bvh-sah") continue;
        for (const auto& p : h["params"]) {
            if (p["name"] != "bins") continue;
            seen = true;
            EXPECT_EQ(p["kind"], "integer");
            EXPECT_EQ(p["min"], 2);
            EXPECT_EQ(p["max"], 256);
            EXPECT_EQ(p["default"], 16);
        }
    }
    EXPECT_TRUE(seen);
    const CliRun text = run_cli("list", 60);
    EXPECT_NE(text.out.find("bins=16"), std::string::npos);
    EXPECT_NE(text.out.find("[integer in [2, 256]]"), std::string::npos);
    const CliRun bad = run_cli("build builtin:tetra:1 -H bvh-sah --set bins=1", 60);
    EXPECT_EQ(bad.code, 2);
    EXPECT_NE(bad.err.find("rtcost: error: --set: bins=1: must be in [2, 256]"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace rtcost::test
