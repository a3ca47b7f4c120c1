// Headless Chromium over --remote-debugging-pipe (browser.h).
#include "tests/browser.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

namespace iblcheck::testutil {

using nlohmann::json;

namespace {
std::string base64_decode(const std::string& in) {
    auto val = [](char c) -> int {
        if (c >= 'A' && c <= 'Z') return c - 'A';
        if (c >= 'a' && c <= 'z') return c - 'a' + 26;
        if (c >= '0' && c <= '9') return c - '0' + 52;
        if (c == '+') return 62;
        if (c == '/') return 63;
        return -1;
    };
    std::string out;
    int bits = 0, acc = 0;
    for (char c : in) {
        int v = val(c);
        if (v < 0) continue;
        acc = (acc << 6) | v;
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out += char((acc >> bits) & 0xff);
        }
    }
    return out;
}
} // namespace

bool Browser::available() { return ::access(kChromium, X_OK) == 0; }

Browser::Browser(const std::filesystem::path& profile, int width, int height) : width_(width), height_(height) {
    ::signal(SIGPIPE, SIG_IGN); // a browser that died must fail the test, not kill it
    int to[2], from[2];
    if (::pipe(to) != 0 || ::pipe(from) != 0) throw std::runtime_error("browser: pipe() failed");
    const std::string profile_arg = "--user-data-dir=" + profile.string();
    pid_ = ::fork();
    if (pid_ < 0) throw std::runtime_error("browser: fork() failed");
    if (pid_ == 0) {
        ::setpgid(0, 0); // its own process group: the destructor ends Chromium and its helpers together
        // Out of the way of 3 and 4 first, then onto them (the protocol's fds).
        int r = ::fcntl(to[0], F_DUPFD, 10), w = ::fcntl(from[1], F_DUPFD, 10);
        ::dup2(r, 3);
        ::dup2(w, 4);
        for (int fd = 5; fd < 1024; ++fd) ::close(fd);
        int devnull = ::open("/dev/null", O_RDWR);
        ::dup2(devnull, 0);
        ::dup2(devnull, 1);
        ::dup2(devnull, 2);
        ::execl(kChromium, "chromium", "--headless", "--no-sandbox", "--disable-gpu", "--remote-debugging-pipe", "--no-first-run",
                "--disable-background-networking", "--disable-component-update", "--disable-sync", "--hide-scrollbars",
                "--mute-audio", profile_arg.c_str(), "about:blank", static_cast<char*>(nullptr));
        ::_exit(127);
    }
    ::close(to[0]);
    ::close(from[1]);
    to_browser_ = to[1];
    from_browser_ = from[0];
    const json target = call("Target.createTarget", {{"url", "about:blank"}}, false);
    const json attached = call("Target.attachToTarget", {{"targetId", target["targetId"]}, {"flatten", true}}, false);
    session_ = attached["sessionId"].get<std::string>();
    call("Runtime.enable", json::object());
    call("Log.enable", json::object());
    call("Page.enable", json::object());
    set_viewport(width, height);
}

Browser::~Browser() {
    if (pid_ > 0) {
        const int group = pid_; // the group the child made for itself (setpgid above)
        bool reaped = false;
        try {
            send({{"id", ++next_id_}, {"method", "Browser.close"}});
        } catch (...) {}
        for (int i = 0; i < 50 && !reaped; ++i) { // up to 5 s for a clean exit
            reaped = ::waitpid(group, nullptr, WNOHANG) == group;
            if (!reaped) std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
        ::kill(-group, SIGKILL); // whatever is left of it (helper processes)
        if (!reaped) ::waitpid(group, nullptr, 0);
    }
    if (to_browser_ >= 0) ::close(to_browser_);
    if (from_browser_ >= 0) ::close(from_browser_);
}

void Browser::send(const json& message) {
    const std::string s = message.dump() + std::string(1, '\0');
    size_t done = 0;
    while (done < s.size()) {
        ssize_t n = ::write(to_browser_, s.data() + done, s.size() - done);
        if (n <= 0) throw std::runtime_error("browser: Chromium is gone (write failed)");
        done += size_t(n);
    }
}

json Browser::receive(double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    for (;;) {
        if (size_t z = buffer_.find('\0'); z != std::string::npos) {
            json j = json::parse(buffer_.substr(0, z));
            buffer_.erase(0, z + 1);
            return j;
        }
        const double left = std::chrono::duration<double>(end - std::chrono::steady_clock::now()).count();
        if (left <= 0) throw std::runtime_error(fmt::format("browser: no answer from Chromium in {} s", timeout_s));
        pollfd p{from_browser_, POLLIN, 0};
        if (::poll(&p, 1, int(std::ceil(left * 1000))) <= 0) continue;
        char buf[1 << 16];
        ssize_t n = ::read(from_browser_, buf, sizeof buf);
        if (n <= 0) throw std::runtime_error("browser: Chromium is gone (read failed)");
        buffer_.append(buf, size_t(n));
    }
}

void Browser::note_event(const json& m) {
    const std::string method = m.value("method", "");
    const json& p = m.contains("params") ? m["params"] : json();
    if (method == "Runtime.exceptionThrown") {
        const json& d = p["exceptionDetails"];
        std::string text = d.value("text", "exception");
        if (d.contains("exception") && d["exception"].contains("description"))
            text += ": " + d["exception"]["description"].get<std::string>();
        errors_.push_back("uncaught " + text);
    } else if (method == "Runtime.consoleAPICalled" && (p.value("type", "") == "error" || p.value("type", "") == "assert")) {
        std::string text;
        for (const json& a : p["args"])
            text += (text.empty() ? "" : " ") + (a.contains("value") ? a["value"].dump() : a.value("description", ""));
        errors_.push_back("console.error " + text);
    } else if (method == "Log.entryAdded" && p["entry"].value("level", "") == "error") {
        errors_.push_back("log " + p["entry"].value("text", "") + " " + p["entry"].value("url", ""));
    }
}

json Browser::call(const std::string& method, const json& params, bool session) {
    const int id = ++next_id_;
    json m = {{"id", id}, {"method", method}, {"params", params}};
    if (session) m["sessionId"] = session_;
    send(m);
    for (;;) {
        json r = receive(60);
        if (r.contains("id") && r["id"] == id) {
            if (r.contains("error")) throw std::runtime_error("browser: " + method + ": " + r["error"].dump());
            return r.value("result", json::object());
        }
        note_event(r);
    }
}

void Browser::set_viewport(int width, int height) {
    width_ = width;
    height_ = height;
    call("Emulation.setDeviceMetricsOverride",
         {{"width", width}, {"height", height}, {"deviceScaleFactor", 1}, {"mobile", false}});
}

void Browser::open(const std::string& url, const std::string& ready_expr, double timeout_s) {
    call("Page.navigate", {{"url", url}});
    if (!wait_for(ready_expr, timeout_s))
        throw std::runtime_error(fmt::format("browser: {} not ready after {} s ({})", url, timeout_s, ready_expr));
}

json Browser::eval(const std::string& expr) {
    json r = call("Runtime.evaluate", {{"expression", expr}, {"returnByValue", true}, {"awaitPromise", true}});
    if (r.contains("exceptionDetails")) {
        const json& d = r["exceptionDetails"];
        std::string text = d.value("text", "exception");
        if (d.contains("exception") && d["exception"].contains("description"))
            text += ": " + d["exception"]["description"].get<std::string>();
        throw std::runtime_error("browser: " + expr.substr(0, 120) + ": " + text);
    }
    return r["result"].value("value", json());
}

bool Browser::wait_for(const std::string& expr, double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end) {
        if (eval("!!(" + expr + ")") == true) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
}

void Browser::mouse_move(double x, double y) { call("Input.dispatchMouseEvent", {{"type", "mouseMoved"}, {"x", x}, {"y", y}}); }

void Browser::click(double x, double y) {
    mouse_move(x, y);
    call("Input.dispatchMouseEvent", {{"type", "mousePressed"}, {"x", x}, {"y", y}, {"button", "left"}, {"clickCount", 1}});
    call("Input.dispatchMouseEvent", {{"type", "mouseReleased"}, {"x", x}, {"y", y}, {"button", "left"}, {"clickCount", 1}});
}

std::pair<double, double> Browser::centre_of(const std::string& selector) {
    const json r = eval(
        fmt::format("(function(){{var el=document.querySelector({});if(!el)return null;el.scrollIntoView({{block:'center'}});"
                    "var b=el.getBoundingClientRect();return [b.left+b.width/2,b.top+b.height/2];}})()",
                    json(selector).dump()));
    if (!r.is_array()) throw std::runtime_error("browser: nothing matches " + selector);
    return {r[0].get<double>(), r[1].get<double>()};
}

std::string Browser::screenshot(bool full_page) {
    json params = {{"format", "png"}};
    if (full_page) {
        const double h = eval("document.documentElement.scrollHeight").get<double>();
        params["captureBeyondViewport"] = true;
        params["clip"] = {{"x", 0}, {"y", 0}, {"width", width_}, {"height", h}, {"scale", 1}};
    }
    return base64_decode(call("Page.captureScreenshot", params)["data"].get<std::string>());
}

} // namespace iblcheck::testutil
