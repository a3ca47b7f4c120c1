#include "child_render.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/core.h>

#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "image_io/image_io.h"
#include "kernel/errors.h"

extern char** environ;

namespace fs = std::filesystem;

namespace iblcheck {

fs::path iblcheck_executable() {
    std::error_code ec;
    fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (!ec && self.filename() == "iblcheck") return self;
    fs::path built = IBLCHECK_CLI_PATH;
    if (fs::exists(built, ec)) return built;
    throw EnvironmentError(built.string() + ": the iblcheck executable is not built (child renders need it)");
}

namespace {
std::string tail_of(const fs::path& log, size_t max_chars = 1500) {
    std::ifstream f(log);
    std::stringstream ss;
    ss << f.rdbuf();
    std::string s = ss.str();
    return s.size() > max_chars ? "..." + s.substr(s.size() - max_chars) : s;
}

// This process's environment with `env` added or replaced: built here, passed to posix_spawn,
// never installed in this process.
std::vector<std::string> child_environment(const std::map<std::string, std::string>& env) {
    std::vector<std::string> out;
    for (char** e = environ; *e; ++e) {
        std::string kv = *e;
        std::string key = kv.substr(0, kv.find('='));
        if (!env.count(key)) out.push_back(kv);
    }
    for (const auto& [k, v] : env) out.push_back(k + "=" + v);
    return out;
}

std::vector<char*> c_strings(std::vector<std::string>& v) {
    std::vector<char*> out;
    for (auto& s : v) out.push_back(s.data());
    out.push_back(nullptr);
    return out;
}
} // namespace

ChildRender render_in_child(const TestSpec& spec, const std::map<std::string, std::string>& env, const std::string& device) {
    char dir_template[] = "/tmp/iblcheck-child-XXXXXX";
    if (!mkdtemp(dir_template)) throw EnvironmentError(std::string("/tmp: cannot create a folder: ") + std::strerror(errno));
    const fs::path dir = dir_template;
    const fs::path exr = dir / "render.exr", json_file = dir / "render.json", log = dir / "log.txt";

    std::vector<std::string> args = {iblcheck_executable().string(),
                                     "render",
                                     "--scene",
                                     spec.scene,
                                     "--method",
                                     spec.method,
                                     "--env",
                                     spec.env,
                                     "--out",
                                     exr.string(),
                                     "--json",
                                     json_file.string()};
    if (spec.width > 0) args.insert(args.end(), {"--size", fmt::format("{}x{}", spec.width, spec.height)});
    if (!device.empty()) args.insert(args.end(), {"--device", device});
    for (const auto& [k, v] : spec.options.values()) args.insert(args.end(), {"--set", k + "=" + v});
    if (!spec.shader.empty()) args.insert(args.end(), {"--shader", spec.shader});
    std::vector<std::string> envs = child_environment(env);
    std::vector<char*> argv = c_strings(args), envp = c_strings(envs);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    pid_t pid = 0;
    int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), envp.data());
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
        fs::remove_all(dir);
        throw EnvironmentError(fmt::format("{}: cannot start a child render: {}", args[0], std::strerror(rc)));
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    std::string env_text;
    for (const auto& [k, v] : env) env_text += k + "=" + v + " ";
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::string out = tail_of(log);
        fs::remove_all(dir);
        throw Error(fmt::format("child render ({}{} {} {}) failed with {} {}: {}", env_text, spec.method, spec.scene, spec.env,
                                WIFEXITED(status) ? "exit code" : "signal",
                                WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status), out));
    }
    ChildRender r;
    r.image = read_image(exr.string()).pixels;
    std::ifstream f(json_file);
    r.provenance = nlohmann::json::parse(f, nullptr, false).value("provenance", nlohmann::json::object());
    fs::remove_all(dir);
    return r;
}

} // namespace iblcheck
