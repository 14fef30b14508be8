// The README's examples run as written: every `build/rtcost ...` line of its sh code blocks is
// run from the repository root (with the binary under test in place of build/rtcost) and must
// exit 0. Lines that need files outside the repository run only when
// those files are present.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace fs = std::filesystem;

namespace {

std::vector<std::string> readme_commands() {
    std::ifstream in(fs::path(RTCOST_SOURCE_DIR) / "README.md");
    std::vector<std::string> out;
    std::string line;
    bool in_sh = false;
    while (std::getline(in, line)) {
        if (line.rfind("```", 0) == 0) {
            in_sh = !in_sh && line.rfind("```sh", 0) == 0;
            continue;
        }
        if (!in_sh || line.rfind("build/rtcost", 0) != 0) continue;
        // Drop a trailing comment.
        std::size_t hash = line.find("  #");
        if (hash != std::string::npos) line = line.substr(0, hash);
        out.push_back(line);
    }
    return out;
}

// Paths a command names outside the repository (../shared/..., /usr/share/...).
bool needs_missing_file(const std::string& cmd) {
    std::size_t pos = 0;
    while ((pos = cmd.find_first_of("./", pos)) != std::string::npos) {
        bool start = pos == 0 || cmd[pos - 1] == ' ';
        if (start && (cmd.compare(pos, 3, "../") == 0 || cmd.compare(pos, 5, "/usr/") == 0)) {
            std::size_t end = cmd.find(' ', pos);
            std::string path = cmd.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
            fs::path full = path[0] == '/' ? fs::path(path) : fs::path(RTCOST_SOURCE_DIR) / path;
            if (!fs::exists(full)) return true;
        }
        ++pos;
    }
    return false;
}

TEST(Readme, EveryExampleRunsAsWritten) {
    std::vector<std::string> cmds = readme_commands();
    ASSERT_GE(cmds.size(), 10u) << "README examples not found";
    // The README runs from the repository root with the binary at build/rtcost: run there,
    // with the binary under test in its place.
    fs::path err_file = fs::temp_directory_path() / ("rtcost_readme_" + std::to_string(::getpid()) + ".err");
    std::size_t ran = 0;
    for (const std::string& cmd : cmds) {
        if (needs_missing_file(cmd)) {
            std::cout << "skipped (file not present): " << cmd << "\n";
            continue;
        }
        // The shared folder is found relative to the repository, as the README says.
        std::string shell = "cd " + std::string(RTCOST_SOURCE_DIR) + " && " + std::string(RTCOST_CLI) +
                            cmd.substr(std::string("build/rtcost").size()) + " > /dev/null 2> " + err_file.string();
        int status = std::system(shell.c_str());
        std::ifstream err(err_file);
        std::string msg((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
        EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd << "\n" << msg;
        ++ran;
    }
    EXPECT_GE(ran, 8u);
}

}  // namespace
