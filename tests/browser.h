// Headless Chromium driven over the DevTools protocol, for the report's browser tests and the
// screenshot tool (tests/report_browser_main.cpp). Chromium is started with
// --remote-debugging-pipe: protocol messages are NUL-terminated JSON on fds 3 (to the browser)
// and 4 (from it), so no port, no websocket and no library is needed. Everything the page logs as
// an error (uncaught exceptions, console.error, failed resource loads) is collected.
#pragma once
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace iblcheck::testutil {

class Browser {
  public:
    static constexpr const char* kChromium = "/usr/bin/chromium";
    static bool available();

    // Starts Chromium (own profile folder under `profile`) with a viewport of width x height CSS pixels.
    Browser(const std::filesystem::path& profile, int width, int height);
    ~Browser();
    Browser(const Browser&) = delete;
    Browser& operator=(const Browser&) = delete;

    // Opens `url` and waits (at most timeout_s) until `ready_expr` evaluates to true.
    void open(const std::string& url, const std::string& ready_expr, double timeout_s = 30);
    // Runs `expr` in the page; returns its value (awaited when it is a promise). Throws
    // std::runtime_error with the page's message when it throws.
    nlohmann::json eval(const std::string& expr);
    // Waits until `expr` is true; false on timeout.
    bool wait_for(const std::string& expr, double timeout_s = 10);
    // Real input events at page coordinates (CSS pixels of the viewport).
    void mouse_move(double x, double y);
    void click(double x, double y);
    // Scrolls so that the element matched by `selector` is in view and returns its centre (viewport
    // coordinates); throws when nothing matches.
    std::pair<double, double> centre_of(const std::string& selector);
    void set_viewport(int width, int height);
    // PNG bytes of the viewport, or of the whole page when full_page.
    std::string screenshot(bool full_page);

    const std::vector<std::string>& errors() const { return errors_; }

  private:
    nlohmann::json call(const std::string& method, const nlohmann::json& params, bool session = true);
    void send(const nlohmann::json& message);
    nlohmann::json receive(double timeout_s);
    void note_event(const nlohmann::json& message);

    int pid_ = -1, to_browser_ = -1, from_browser_ = -1;
    int next_id_ = 0;
    std::string session_, buffer_;
    int width_, height_;
    std::vector<std::string> errors_;
};

} // namespace iblcheck::testutil
