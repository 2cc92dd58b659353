// The pathlab-debug window. GLFW, OpenGL and Dear ImGui headers stay in this
// file; everything it shows comes from Session (session.h) and the layer
// views (views.h).
#include "debugtools/gui/app.h"

#include "core/error.h"
#include "debugtools/gui/script.h"
#include "debugtools/gui/views.h"

#define GLFW_INCLUDE_NONE
#include <GL/gl.h>
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <ostream>
#include <utility>

namespace pathlab::debug {
namespace {

constexpr float kPanelWidth = 460.0f;
constexpr double kScriptWaitSeconds = 600.0;
constexpr float kMinZoom = 1.0f / 32.0f, kMaxZoom = 128.0f;
constexpr float kWheelStep = 1.25f;     // zoom factor per wheel notch
constexpr float kDividerGrab = 6.0f;    // screen pixels either side of the split divider
constexpr float kEventsTop = 0.62f;     // the events window starts this far down the image area
constexpr float kJumpZoom = 8.0f;       // a jump to a NaN sample zooms in at least this far

std::string g_glfw_error;  // the last GLFW error, for messages
void glfw_error(int code, const char* text) { g_glfw_error = std::to_string(code) + " " + text; }

ImU32 colour(const unsigned char (&c)[4]) { return IM_COL32(c[0], c[1], c[2], c[3]); }
ImU32 colour(const vec3& display) {
  const auto b = [](float v) { return static_cast<int>(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f); };
  return IM_COL32(b(display.x), b(display.y), b(display.z), 255);
}

// A titled separator between the panel's sections.
void section(const char* title) {
  ImGui::Spacing();
  ImGui::Separator();
  ImGui::TextDisabled("%s", title);
}

std::string format(const char* fmt, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, a);
  return buf;
}

// "R 0.5  G 0.25  B 1" for a layer's pixel (its first three channels).
std::string layer_values(const Layer& layer, int x, int y) {
  if (x < 0 || y < 0 || x >= layer.image.width || y >= layer.image.height) return "(outside the image)";
  const vec3& v = layer.image.at(x, y);
  const std::vector<std::string> names = channel_names(layer);
  std::string out;
  for (int c = 0; c < std::min(layer.count, 3); ++c)
    out += (c ? "  " : "") + names[static_cast<std::size_t>(c)] + " " + format("%.7g", static_cast<double>(v[c]));
  if (layer.count > 3) out += "  (+" + std::to_string(layer.count - 3) + " channels)";
  return out;
}

struct Texture {
  GLuint id = 0;
  int w = 0, h = 0;
  bool present = false;  // the side has the layer shown
};

enum class Compare : std::uint8_t { Off, Tracer, Image };

class App {
 public:
  App(const AppOptions& options, std::ostream& err)
      : options_(options), err_(err), session_(options.session), ui_(options.session), exposure_(options.exposure) {
    if (!options.script.empty()) script_ = load_script(options.script);
    // The layers exist once the render has published its first (empty) snapshot.
    if (!session_.wait_spp(0, 60.0)) throw SystemError("the render did not start");
    session_.snapshot(snap_);
    set_view(options.view);
    sync_ui();
  }
  ~App() { close_window(); }
  App(const App&) = delete;
  App& operator=(const App&) = delete;

  int run();

 private:
  std::pair<int, int> window_size();
  bool open_window();
  void close_window();
  void frame();
  void step_script();
  void run_command(const ScriptCommand& c);
  void upload_textures();
  void upload(Texture& t, const std::vector<Layer>& layers, const Range& range);
  void draw_image();
  void draw_overlay(ImDrawList* dl) const;
  void draw_colour_bar();
  void draw_panel();
  void draw_events();
  void apply(const SessionSettings& next);
  void click(int x, int y);
  void next_nan();
  void set_view(const std::string& name);
  void set_compare(Compare c, const std::string& file = {});
  void zoom_about(float zoom, ImVec2 at);
  void fit();
  void actual_size();
  void centre_on(int x, int y);
  std::vector<std::string> readout_lines() const;
  void screenshot(const std::string& file);
  void sync_ui();
  template <typename F>
  void act(const char* what, F&& f);

  // The image area (left of the panel), image <-> screen.
  ImVec2 area() const;
  ImVec2 to_screen(float x, float y) const { return ImVec2(origin_.x + x * zoom_, origin_.y + y * zoom_); }
  std::pair<int, int> to_pixel(ImVec2 s) const {
    return {static_cast<int>(std::floor((s.x - origin_.x) / zoom_)), static_cast<int>(std::floor((s.y - origin_.y) / zoom_))};
  }
  float divider_x() const { return split_ * area().x; }
  Mapping mapping() const;
  const std::vector<Layer>& other_layers() const { return compare_ == Compare::Tracer ? other_snap_.layers : other_image_; }
  std::string other_label() const;

  const AppOptions& options_;
  std::ostream& err_;
  Session session_;
  SessionSettings ui_;     // what the panel edits
  RenderSettings shown_;   // strategy, depth, spp, seed as the panel shows them
  std::string layer_ = "beauty";
  bool nan_view_ = false;
  std::map<std::string, Mapping> mappings_;  // the user's choice per layer
  float exposure_;
  Range range_;
  Snapshot snap_;
  bool texture_dirty_ = true;

  // Split view: this render on the left of the divider, the other on its right.
  Compare compare_ = Compare::Off;
  std::unique_ptr<Session> other_session_;  // Compare::Tracer
  Snapshot other_snap_;
  std::vector<Layer> other_image_;          // Compare::Image
  std::string other_file_;
  float split_ = 0.5f;                      // divider, as a fraction of the image area's width

  GLFWwindow* window_ = nullptr;
  Texture texture_, other_texture_;
  bool imgui_ready_ = false;
  float zoom_ = 1.0f;            // screen pixels per image pixel
  ImVec2 origin_{0.0f, 0.0f};    // screen position of the image's top-left corner
  float panel_width_ = kPanelWidth;
  bool dragging_divider_ = false, dragged_ = false, pressed_on_image_ = false;

  std::optional<std::pair<int, int>> hover_;  // the pixel under the mouse (or the script's)
  // The script's mouse: a position in window coordinates, a click in
  // progress (1: the button goes down this frame, 2: it comes up), a drag
  // (1: down at the start, 2: moved to the end, 3: up) and wheel notches,
  // fed to ImGui in place of the real mouse so that the script takes the same
  // path as a person's hand.
  std::optional<ImVec2> script_mouse_;
  int script_click_ = 0, script_drag_ = 0;
  bool script_moved_ = false;  // the mouse moved: let a frame see it before the next command
  ImVec2 drag_from_, drag_to_;
  float script_wheel_ = 0.0f;
  int retrace_sample_ = 0;
  std::string scene_path_, vtk_path_ = "out/path.vtp", save_path_ = "out/debug.exr", compare_path_;
  std::string status_, nan_status_;
  float events_font_ = 1.0f;
  std::optional<float> events_top_;  // where the events window starts (it covers the image below)

  std::vector<ScriptCommand> script_;
  std::size_t next_command_ = 0;
  std::optional<std::chrono::steady_clock::time_point> waiting_since_;
  std::string pending_screenshot_;
  bool in_command_ = false;  // running a script command
  bool quit_ = false;
  int exit_code_ = 0;
};

void App::sync_ui() {
  ui_ = session_.settings();
  shown_ = session_.render_settings();
  scene_path_ = ui_.scene_file;
}

template <typename F>
void App::act(const char* what, F&& f) {
  try {
    f();
    status_.clear();
  } catch (const std::exception& e) {
    status_ = std::string(what) + ": " + e.what();
    if (in_command_) throw;  // a script stops at its first failing command
  }
}

Mapping App::mapping() const {
  if (const auto it = mappings_.find(layer_); it != mappings_.end()) return it->second;
  const Layer* l = find_layer(snap_.layers, layer_);
  if (!l) l = find_layer(other_layers(), layer_);
  return l ? default_mapping(*l) : Mapping::Tone;
}

std::string App::other_label() const {
  if (compare_ == Compare::Tracer) return other_session_ ? std::string(other_session_->settings().tracer) : "";
  return std::filesystem::path(other_file_).filename().string();
}

void App::set_view(const std::string& name) {
  if (name == "nan") {
    nan_view_ = true;
  } else {
    if (!find_layer(snap_.layers, name) && !find_layer(other_layers(), name)) {
      std::string known;
      for (const Layer& l : snap_.layers) known += (known.empty() ? "" : ", ") + l.name;
      for (const Layer& l : other_layers())
        if (!find_layer(snap_.layers, l.name)) known += ", " + l.name;
      throw InputError("unknown view '" + name + "' (layers: " + known + "; or nan)");
    }
    nan_view_ = false;
    layer_ = name;
  }
  texture_dirty_ = true;
}

void App::set_compare(Compare c, const std::string& file) {
  if (c == Compare::Image) {
    other_image_ = read_image_layers(file);  // throws before anything changes
    other_file_ = file;
  } else {
    other_image_.clear();
    other_file_.clear();
  }
  other_session_.reset();
  other_snap_ = Snapshot{};
  if (c == Compare::Tracer) {
    SessionSettings s = session_.settings();
    s.tracer = s.tracer == "reference" ? "wavefront" : "reference";
    // Per-bounce layers on both sides (compare them layer by layer); stage
    // buffers only where the wavefront is.
    if (s.intermediate == SessionSettings::Intermediate::StageBuffers && s.tracer != "wavefront")
      s.intermediate = SessionSettings::Intermediate::None;
    other_session_ = std::make_unique<Session>(s);
  }
  compare_ = c;
  texture_dirty_ = true;
}

void App::apply(const SessionSettings& next) {
  act("restart", [&] {
    session_.apply(next);
    if (compare_ == Compare::Tracer) set_compare(Compare::Tracer);  // the other tracer follows the settings
  });
  sync_ui();
  texture_dirty_ = true;
  if (window_) {  // another scene may have another size
    const auto [w, h] = window_size();
    glfwSetWindowSize(window_, w, h);
  }
}

void App::click(int x, int y) {
  act("retrace", [&] {
    session_.retrace(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y),
                     static_cast<std::uint32_t>(std::max(retrace_sample_, 0)));
  });
}

void App::next_nan() {
  act("next NaN/Inf", [&] {
    const auto& cur = session_.current_retrace();
    const auto r = cur ? session_.next_nonfinite(snap_, static_cast<int>(cur->x), static_cast<int>(cur->y), cur->sample)
                       : session_.next_nonfinite(snap_, -1, -1, std::nullopt);
    if (!r) {
      nan_status_ = "no NaN/Inf sample in the render so far";
      if (in_command_) throw InputError(nan_status_);
      return;
    }
    retrace_sample_ = static_cast<int>(r->sample);
    session_.retrace(r->x, r->y, r->sample);
    zoom_ = std::max(zoom_, kJumpZoom);
    centre_on(static_cast<int>(r->x), static_cast<int>(r->y));
    hover_ = std::pair(static_cast<int>(r->x), static_cast<int>(r->y));
    nan_status_ = "NaN/Inf: pixel (" + std::to_string(r->x) + ", " + std::to_string(r->y) + ") sample " +
                  std::to_string(r->sample);
  });
}

ImVec2 App::area() const {
  ImVec2 d = ImGui::GetIO().DisplaySize;
  if (window_) {  // also before the first frame has set DisplaySize
    int w = 0, h = 0;
    glfwGetWindowSize(window_, &w, &h);
    d = ImVec2(static_cast<float>(w), static_cast<float>(h));
  }
  return ImVec2(std::max(d.x - panel_width_, 1.0f), std::max(d.y, 1.0f));
}

void App::zoom_about(float zoom, ImVec2 at) {
  zoom = std::clamp(zoom, kMinZoom, kMaxZoom);
  origin_ = ImVec2(at.x - (at.x - origin_.x) * zoom / zoom_, at.y - (at.y - origin_.y) * zoom / zoom_);
  zoom_ = zoom;
}

void App::fit() {
  const ImVec2 a = area();
  const float w = static_cast<float>(session_.scene().film.width), h = static_cast<float>(session_.scene().film.height);
  zoom_ = std::clamp(std::min(a.x / w, a.y / h), kMinZoom, kMaxZoom);
  origin_ = ImVec2(0.5f * (a.x - w * zoom_), 0.5f * (a.y - h * zoom_));
}

void App::actual_size() {
  zoom_ = 1.0f;
  origin_ = ImVec2(0.0f, 0.0f);
}

// Centres pixel (x, y) in the part of the image area the events window leaves free.
void App::centre_on(int x, int y) {
  const ImVec2 a = area();
  const float visible = std::clamp(events_top_.value_or(kEventsTop * a.y), 0.25f * a.y, a.y);
  origin_ = ImVec2(0.5f * a.x - (static_cast<float>(x) + 0.5f) * zoom_, 0.5f * visible - (static_cast<float>(y) + 0.5f) * zoom_);
}

// The window for the current scene: the image 1:1 (or scaled down to fit
// 1600x1000) and the panel beside it. Sets the zoom to match.
std::pair<int, int> App::window_size() {
  const Scene& sc = session_.scene();
  zoom_ = std::min({1.0f, 1000.0f / static_cast<float>(sc.film.height),
                    (1600.0f - kPanelWidth) / static_cast<float>(sc.film.width)});
  origin_ = ImVec2(0.0f, 0.0f);
  // At least 800 pixels beside the panel, to zoom into.
  return {std::max(static_cast<int>(static_cast<float>(sc.film.width) * zoom_), 800) + static_cast<int>(panel_width_),
          std::max(static_cast<int>(static_cast<float>(sc.film.height) * zoom_), 720)};
}

bool App::open_window() {
  glfwSetErrorCallback(glfw_error);
  if (!glfwInit()) return false;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 0);
  const auto [w, h] = window_size();
  window_ = glfwCreateWindow(w, h, "pathlab-debug", nullptr, nullptr);
  if (!window_) return false;
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(script_.empty() ? 1 : 0);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the user's folder
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window_, true);
  ImGui_ImplOpenGL3_Init("#version 130");
  imgui_ready_ = true;
  glGenTextures(1, &texture_.id);
  glGenTextures(1, &other_texture_.id);
  return true;
}

void App::close_window() {
  if (imgui_ready_) {
    for (GLuint t : {texture_.id, other_texture_.id})
      if (t) glDeleteTextures(1, &t);
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    imgui_ready_ = false;
  }
  if (window_) glfwDestroyWindow(window_);
  window_ = nullptr;
  glfwTerminate();
}

void App::upload(Texture& t, const std::vector<Layer>& layers, const Range& range) {
  const Layer* layer = find_layer(layers, nan_view_ ? "beauty" : layer_);
  t.present = layer != nullptr && layer->image.width > 0;
  if (!t.present) return;
  std::vector<std::uint8_t> rgba;
  if (nan_view_) {
    const Layer* counts = find_layer(layers, "nonfinite");
    rgba = counts ? nonfinite_rgba(*layer, *counts, exposure_) : layer_rgba(*layer, Mapping::Tone, exposure_ - 2.0f, range);
  } else {
    rgba = layer_rgba(*layer, mapping(), exposure_, range);
  }
  glBindTexture(GL_TEXTURE_2D, t.id);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);  // magnified pixels stay square
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA, layer->image.width, layer->image.height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
               rgba.data());
  t.w = layer->image.width;
  t.h = layer->image.height;
}

void App::upload_textures() {
  bool changed = session_.snapshot(snap_);
  if (other_session_) changed |= other_session_->snapshot(other_snap_);
  if (!changed && !texture_dirty_) return;
  texture_dirty_ = false;
  // One range for both sides of a split view, so equal colours mean equal values.
  const Mapping m = mapping();
  range_ = Range{};
  bool first = true;
  const std::vector<Layer>* sides[] = {&snap_.layers, &other_layers()};
  for (const std::vector<Layer>* side : sides) {
    if (const Layer* l = find_layer(*side, layer_)) {
      const Range r = auto_range(*l, m);
      if (!r.valid) continue;
      range_.lo = first ? r.lo : std::min(range_.lo, r.lo);
      range_.hi = first ? r.hi : std::max(range_.hi, r.hi);
      range_.valid = true;
      first = false;
    }
  }
  upload(texture_, snap_.layers, range_);
  if (compare_ != Compare::Off) upload(other_texture_, other_layers(), range_);
}

void App::draw_overlay(ImDrawList* dl) const {
  const auto& r = session_.current_retrace();
  if (!r || r->lines.empty()) return;
  const FilmProjection& proj = session_.projection();
  const auto screen = [&](vec2 f) { return to_screen(f.x, f.y); };
  const auto project = [&](const vec3& p) -> std::optional<ImVec2> {
    if (const auto f = proj.project(p)) return screen(*f);
    return std::nullopt;
  };
  // Shadow rays under the path.
  for (const PathLine& line : r->lines) {
    if (line.kind != PathLine::Kind::Shadow) continue;
    const auto a = project(line.points[0].p), b = project(line.points[1].p);
    if (a && b)
      dl->AddLine(*a, *b, colour((line.points[0].flags & kPointNeeVisible) ? kShadowVisibleColour : kShadowBlockedColour),
                  1.0f);
  }
  // The path: from where the camera ray crosses the film, vertex to vertex.
  const PathLine& path = r->lines.front();
  std::vector<std::optional<ImVec2>> pts;
  for (const PathPoint& p : path.points) pts.push_back((p.flags & kPointCamera) ? std::optional(screen(r->film)) : project(p.p));
  for (std::size_t i = 1; i < pts.size(); ++i)
    if (pts[i - 1] && pts[i]) dl->AddLine(*pts[i - 1], *pts[i], colour(kPathColour), 2.0f);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!pts[i] || (path.points[i].flags & (kPointCamera | kPointEscape))) continue;
    dl->AddCircleFilled(*pts[i], 4.0f, colour(kVertexColour));
  }
  dl->AddCircle(screen(r->film), 6.0f, colour(kPathColour), 0, 2.0f);
}

void App::draw_image() {
  const ImVec2 a = area();
  ImDrawList* dl = ImGui::GetBackgroundDrawList();
  const auto image = [&](const Texture& t, float x0, float x1) {
    dl->PushClipRect(ImVec2(x0, 0), ImVec2(x1, a.y), false);
    if (t.present && t.w > 0)
      dl->AddImage(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(t.id)), origin_,
                   to_screen(static_cast<float>(t.w), static_cast<float>(t.h)));
    dl->PopClipRect();
  };
  const bool split = compare_ != Compare::Off;
  const float divider = split ? divider_x() : a.x;
  image(texture_, 0.0f, divider);
  dl->PushClipRect(ImVec2(0, 0), ImVec2(divider, a.y), false);
  draw_overlay(dl);
  dl->PopClipRect();
  if (split) {
    image(other_texture_, divider, a.x);
    dl->AddLine(ImVec2(divider, 0), ImVec2(divider, a.y), IM_COL32(255, 255, 255, 255), 2.0f);
    const std::string left = session_.settings().tracer == "wavefront" && compare_ == Compare::Tracer
                                 ? "wavefront" : compare_ == Compare::Tracer ? "reference" : "this render";
    const std::string right = other_label() + (other_texture_.present ? "" : " (no layer " + layer_ + ")");
    dl->AddText(ImVec2(std::max(divider - 8.0f - ImGui::CalcTextSize(left.c_str()).x, 4.0f), a.y - 22.0f),
                IM_COL32(255, 255, 255, 255), left.c_str());
    dl->AddText(ImVec2(divider + 8.0f, a.y - 22.0f), IM_COL32(255, 255, 255, 255), right.c_str());
  }

  // The mouse, unless a window has it.
  const ImGuiIO& io = ImGui::GetIO();
  if (io.WantCaptureMouse) return;
  const ImVec2 m = io.MousePos;
  const bool in_area = m.x >= 0 && m.y >= 0 && m.x < a.x && m.y < a.y;
  if (in_area && io.MouseWheel != 0.0f) zoom_about(zoom_ * std::pow(kWheelStep, io.MouseWheel), m);
  if (ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {
    pressed_on_image_ = in_area;
    dragged_ = false;
    dragging_divider_ = in_area && split && std::abs(m.x - divider) <= kDividerGrab;
  }
  // Drag with the left button to pan (or move the divider), with the middle or right button to pan.
  if (pressed_on_image_ && ImGui::IsMouseDragging(ImGuiMouseButton_Left, 3.0f)) {
    dragged_ = true;
    if (dragging_divider_) split_ = std::clamp(m.x / a.x, 0.0f, 1.0f);
    else origin_ = ImVec2(origin_.x + io.MouseDelta.x, origin_.y + io.MouseDelta.y);
  }
  for (ImGuiMouseButton b : {ImGuiMouseButton_Middle, ImGuiMouseButton_Right})
    if (in_area && ImGui::IsMouseDragging(b, 1.0f)) origin_ = ImVec2(origin_.x + io.MouseDelta.x, origin_.y + io.MouseDelta.y);
  if (!in_area) return;
  const auto [x, y] = to_pixel(m);
  if (x >= 0 && y >= 0 && x < snap_.width && y < snap_.height) {
    hover_ = std::pair(x, y);
    // A click is a press and release without a drag.
    if (ImGui::IsMouseReleased(ImGuiMouseButton_Left) && pressed_on_image_ && !dragged_) click(x, y);
  }
}

void App::draw_colour_bar() {
  const Mapping m = mapping();
  if (nan_view_ || (m != Mapping::Linear && m != Mapping::Log)) return;
  const float width = ImGui::GetContentRegionAvail().x, height = 14.0f;
  const ImVec2 p = ImGui::GetCursorScreenPos();
  ImDrawList* dl = ImGui::GetWindowDrawList();
  constexpr int kSteps = 64;
  for (int i = 0; i < kSteps; ++i) {
    const float x0 = p.x + width * static_cast<float>(i) / kSteps, x1 = p.x + width * static_cast<float>(i + 1) / kSteps;
    dl->AddRectFilled(ImVec2(x0, p.y), ImVec2(x1 + 0.5f, p.y + height),
                      colour(ramp_colour((static_cast<float>(i) + 0.5f) / kSteps)));
  }
  ImGui::Dummy(ImVec2(width, height));
  if (!range_.valid) {
    ImGui::TextUnformatted(m == Mapping::Log ? "no positive finite value" : "no finite value");
    return;
  }
  const bool log = m == Mapping::Log;
  const double lo = range_.lo, hi = range_.hi;
  const double mid = log ? std::sqrt(lo * hi) : 0.5 * (lo + hi);
  const std::string l = format("%.4g", lo), c = format("%.4g", mid), r = format("%.4g", hi);
  ImGui::TextUnformatted(l.c_str());
  ImGui::SameLine(0.5f * (width - ImGui::CalcTextSize(c.c_str()).x));
  ImGui::TextUnformatted(c.c_str());
  ImGui::SameLine(width - ImGui::CalcTextSize(r.c_str()).x);
  ImGui::TextUnformatted(r.c_str());
  ImGui::TextDisabled("%s range of the channel mean, auto (min..max%s)", log ? "log" : "linear",
                      log ? " of positive values" : "");
}

std::vector<std::string> App::readout_lines() const {
  std::vector<std::string> out;
  if (!hover_) return out;
  const auto [x, y] = *hover_;
  const PixelReadout p = session_.readout(snap_, x, y);
  out.push_back("pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")  " + std::to_string(p.samples) + " samples");
  const std::string shown = nan_view_ ? "nonfinite" : layer_;
  if (const Layer* l = find_layer(snap_.layers, shown)) out.push_back(shown + ": " + layer_values(*l, x, y));
  if (compare_ != Compare::Off) {
    const Layer* o = find_layer(other_layers(), shown);
    out.push_back(other_label() + " " + shown + ": " + (o ? layer_values(*o, x, y) : "(no such layer)"));
  }
  out.push_back("radiance " + format("%.5g", static_cast<double>(p.radiance.x)) + " " +
                format("%.5g", static_cast<double>(p.radiance.y)) + " " + format("%.5g", static_cast<double>(p.radiance.z)) +
                "  std error " + format("%.3g", static_cast<double>(max_component(p.std_error))));
  out.push_back("path length " + format("%.2f", static_cast<double>(p.path_length)) + "   NaN/Inf samples " +
                std::to_string(p.nonfinite));
  if (const auto& r = session_.current_retrace())
    out.push_back("retraced: pixel (" + std::to_string(r->x) + ", " + std::to_string(r->y) + ") sample " +
                  std::to_string(r->sample) + " radiance " + format("%.5g", static_cast<double>(r->path.result().x)) +
                  " " + format("%.5g", static_cast<double>(r->path.result().y)) + " " +
                  format("%.5g", static_cast<double>(r->path.result().z)));
  out.push_back("zoom " + format("%.6g", static_cast<double>(zoom_)) + "  origin " + format("%.6g", static_cast<double>(origin_.x)) +
                " " + format("%.6g", static_cast<double>(origin_.y)));
  return out;
}

void App::draw_panel() {
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  // Anchored at the right edge; its width from the "panel width" slider (or an edge drag).
  ImGui::SetNextWindowPos(ImVec2(display.x, 0), ImGuiCond_Always, ImVec2(1.0f, 0.0f));
  ImGui::SetNextWindowSize(ImVec2(panel_width_, display.y), ImGuiCond_Always);
  ImGui::Begin("pathlab-debug", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoCollapse);
  panel_width_ = std::clamp(ImGui::GetWindowWidth(), 300.0f, std::max(300.0f, 0.8f * display.x));
  const Scene& sc = session_.scene();

  // Scene: open a file, save the image.
  ImGui::InputText("scene", &scene_path_);
  ImGui::SameLine();
  if (ImGui::Button("Open")) {
    SessionSettings next = ui_;
    next.scene_file = scene_path_;
    apply(next);
  }
  ImGui::Text("%s  %dx%d", sc.file.empty() ? ("<built-in " + sc.name + ">").c_str() : sc.file.string().c_str(),
              sc.film.width, sc.film.height);
  ImGui::InputText("image", &save_path_);
  ImGui::SameLine();
  if (ImGui::Button("Save")) act("save", [&] { session_.save_image(save_path_, exposure_); });

  // Render controls: any change restarts the render.
  section("render");
  SessionSettings next = ui_;
  bool changed = false;
  int tracer = ui_.tracer == "wavefront" ? 1 : 0;
  if (ImGui::Combo("tracer", &tracer, "reference\0wavefront\0")) next.tracer = tracer ? "wavefront" : "reference", changed = true;
  int strategy = static_cast<int>(shown_.strategy);
  std::string strategies;
  for (Strategy s : kAllStrategies) strategies += std::string(strategy_name(s)) + '\0';
  if (ImGui::Combo("strategy", &strategy, strategies.c_str())) next.strategy = static_cast<Strategy>(strategy), changed = true;
  int depth = shown_.max_depth, spp = shown_.spp;
  // Typed numbers apply on Enter (or the +/- buttons), not at every keystroke.
  const ImGuiInputTextFlags on_enter = ImGuiInputTextFlags_EnterReturnsTrue;
  if (ImGui::InputInt("max depth", &depth, 1, 4, on_enter) && depth >= -1) next.max_depth = depth, changed = true;
  if (ImGui::InputInt("spp target", &spp, 1, 64, on_enter) && spp >= 1) next.spp = spp, changed = true;
  std::uint64_t seed = next.seed.value_or(session_.scene().render.seed);
  if (ImGui::InputScalar("seed", ImGuiDataType_U64, &seed, nullptr, nullptr, nullptr, on_enter))
    next.seed = seed, changed = true;
  changed |= ImGui::Checkbox("freeze seed", &next.freeze_seed);
  int threads = next.all_threads ? 1 : 0;
  bool threads_changed = ImGui::RadioButton("1 thread", &threads, 0);
  ImGui::SameLine();
  threads_changed |= ImGui::RadioButton("all threads", &threads, 1);
  if (threads_changed) next.all_threads = threads == 1, changed = true;
  int materials = static_cast<int>(next.materials);
  if (ImGui::Combo("materials", &materials, "as authored\0white Lambert\0mirror\0"))
    next.materials = static_cast<MaterialOverride>(materials), changed = true;
  // Intermediate layers (they show up in the buffer list below).
  int intermediate = static_cast<int>(next.intermediate);
  if (ImGui::Combo("layers", &intermediate, "final only\0+ per bounce\0+ stage buffers\0"))
    next.intermediate = static_cast<SessionSettings::Intermediate>(intermediate), changed = true;
  if (next.intermediate == SessionSettings::Intermediate::StageBuffers) {
    int vertex = next.stage_vertex;
    if (ImGui::InputInt("at vertex", &vertex, 1, 1, on_enter) && vertex >= 1) next.stage_vertex = vertex, changed = true;
  }
  if (ImGui::Button("Restart") || changed) apply(next);
  ImGui::Text("%d / %d spp  seed %llu  %.1f s", snap_.spp_done, snap_.spp_target,
              static_cast<unsigned long long>(snap_.seed), snap_.seconds);

  // Views: every layer of the render (and of a compared image), the NaN map.
  section("view");
  std::vector<std::string> names;
  for (const Layer& l : snap_.layers) names.push_back(l.name);
  for (const Layer& l : other_layers())
    if (!find_layer(snap_.layers, l.name)) names.push_back(l.name);
  names.push_back("nan");
  const std::string current = nan_view_ ? "nan" : layer_;
  if (ImGui::BeginCombo("buffer", current == "nan" ? "NaN/Inf map" : current.c_str())) {
    for (const std::string& n : names)
      if (ImGui::Selectable(n == "nan" ? "NaN/Inf map" : n.c_str(), n == current)) act("view", [&] { set_view(n); });
    ImGui::EndCombo();
  }
  if (!nan_view_) {
    int m = static_cast<int>(mapping());
    if (ImGui::Combo("scale", &m, "tone (exposure)\0normal\0id colours\0linear range\0log range\0"))
      mappings_[layer_] = static_cast<Mapping>(m), texture_dirty_ = true;
  }
  if (ImGui::SliderFloat("exposure", &exposure_, -10.0f, 10.0f, "%.1f stops")) texture_dirty_ = true;
  draw_colour_bar();
  if (ImGui::Button("Fit")) fit();
  ImGui::SameLine();
  if (ImGui::Button("1:1")) actual_size();
  ImGui::SameLine();
  ImGui::Text("zoom %.3g  (wheel: zoom, drag: pan)", static_cast<double>(zoom_));
  ImGui::SetNextItemWidth(140.0f);
  ImGui::SliderFloat("panel width", &panel_width_, 300.0f, std::max(300.0f, 0.8f * display.x), "%.0f");
  if (ImGui::Button("Next NaN/Inf sample")) next_nan();
  if (!nan_status_.empty()) {
    ImGui::SameLine();
    ImGui::TextUnformatted(nan_status_.c_str());
  }

  // Split view.
  section("compare");
  int cmp = static_cast<int>(compare_);
  if (ImGui::Combo("split view", &cmp, "off\0other tracer\0image file\0") && static_cast<Compare>(cmp) != Compare::Image)
    act("compare", [&] { set_compare(static_cast<Compare>(cmp)); });
  ImGui::InputText("exr", &compare_path_);
  ImGui::SameLine();
  if (ImGui::Button("Load")) act("compare", [&] { set_compare(Compare::Image, compare_path_); });
  if (compare_ != Compare::Off) {
    ImGui::SliderFloat("divider", &split_, 0.0f, 1.0f, "%.2f");
    if (compare_ == Compare::Tracer)
      ImGui::Text("%s: %d / %d spp", other_label().c_str(), other_snap_.spp_done, other_snap_.spp_target);
  }

  // The pixel under the mouse.
  section("pixel");
  const std::vector<std::string> lines = readout_lines();
  if (lines.empty()) ImGui::TextUnformatted("hover over the image");
  for (const std::string& l : lines) ImGui::TextUnformatted(l.c_str());

  // The clicked sample.
  section("retrace");
  ImGui::InputInt("sample", &retrace_sample_);
  retrace_sample_ = std::max(retrace_sample_, 0);
  if (const auto& r = session_.current_retrace()) {
    ImGui::Text("pixel (%u, %u) sample %u seed %llu, %s, single-threaded", r->x, r->y, r->sample,
                static_cast<unsigned long long>(r->seed), r->tracer.c_str());
    ImGui::InputText("vtk", &vtk_path_);
    ImGui::SameLine();
    if (ImGui::Button("Export VTK")) act("export", [&] { session_.export_vtk(vtk_path_); });
    ImGui::TextDisabled("its events: the events window");
  } else {
    ImGui::TextUnformatted("click a pixel to replay its sample");
  }
  if (!status_.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", status_.c_str());
  ImGui::End();
}

// The clicked sample's events in a window of their own: movable, resizable,
// with its own text size.
void App::draw_events() {
  const auto& r = session_.current_retrace();
  if (!r) return;
  const ImVec2 a = area();
  ImGui::SetNextWindowPos(ImVec2(0.0f, kEventsTop * a.y), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(a.x, (1.0f - kEventsTop) * a.y), ImGuiCond_FirstUseEver);
  const std::string title = "events: pixel (" + std::to_string(r->x) + ", " + std::to_string(r->y) + ") sample " +
                            std::to_string(r->sample) + "###events";
  const bool open = ImGui::Begin(title.c_str());
  events_top_ = open ? ImGui::GetWindowPos().y : a.y;  // collapsed: only its title bar
  if (open) {
    ImGui::SetNextItemWidth(120.0f);
    ImGui::SliderFloat("text size", &events_font_, 0.7f, 2.0f, "%.1f");
    ImGui::SameLine();
    if (ImGui::Button("Copy")) {
      std::string all;
      for (const std::string& line : r->text) all += line + "\n";
      ImGui::SetClipboardText(all.c_str());
    }
    ImGui::BeginChild("lines", ImVec2(0, 0), true, ImGuiWindowFlags_HorizontalScrollbar);
    ImGui::SetWindowFontScale(events_font_);
    for (const std::string& line : r->text) ImGui::TextUnformatted(line.c_str());
    ImGui::EndChild();
  }
  ImGui::End();
}

void App::run_command(const ScriptCommand& c) {
  using Kind = ScriptCommand::Kind;
  SessionSettings next = session_.settings();
  switch (c.kind) {
    case Kind::WaitSpp: break;  // handled by step_script
    case Kind::Hover:
    case Kind::Click: {
      if (c.x >= session_.scene().film.width || c.y >= session_.scene().film.height)
        throw InputError("pixel (" + std::to_string(c.x) + ", " + std::to_string(c.y) + ") is outside the image");
      // The centre of the pixel, where it is drawn now.
      const ImVec2 s = to_screen(static_cast<float>(c.x) + 0.5f, static_cast<float>(c.y) + 0.5f);
      const ImVec2 a = area();
      if (s.x < 0 || s.y < 0 || s.x >= a.x || s.y >= a.y)
        throw InputError("pixel (" + std::to_string(c.x) + ", " + std::to_string(c.y) +
                         ") is not in view (zoomed or panned away)");
      script_mouse_ = s;
      script_moved_ = true;
      if (c.kind == Kind::Click) script_click_ = 1;
      break;
    }
    case Kind::Mouse: script_mouse_ = ImVec2(static_cast<float>(c.x), static_cast<float>(c.y)), script_moved_ = true; break;
    case Kind::Wheel:
      script_mouse_ = ImVec2(static_cast<float>(c.x), static_cast<float>(c.y));
      script_wheel_ = static_cast<float>(c.dx);
      break;
    case Kind::Drag:
      drag_from_ = ImVec2(static_cast<float>(c.x), static_cast<float>(c.y));
      drag_to_ = ImVec2(static_cast<float>(c.x + c.dx), static_cast<float>(c.y + c.dy));
      script_drag_ = 1;
      break;
    case Kind::Fit: fit(); break;
    case Kind::ActualSize: actual_size(); break;
    case Kind::Readout: {
      std::ofstream out(c.arg);
      for (const std::string& l : readout_lines()) out << l << "\n";
      if (!out) throw InputError(c.arg + ": cannot write the readout");
      break;
    }
    case Kind::NextNan: next_nan(); break;
    case Kind::Compare: set_compare(c.arg == "tracer" ? Compare::Tracer : Compare::Off); break;
    case Kind::CompareImage: set_compare(Compare::Image, c.arg); break;
    case Kind::Split: split_ = c.value; break;
    case Kind::Sample: retrace_sample_ = c.x; break;
    case Kind::View: set_view(c.arg); break;
    case Kind::Scale: mappings_[layer_] = *parse_mapping(c.arg), texture_dirty_ = true; break;
    case Kind::Exposure: exposure_ = c.value, texture_dirty_ = true; break;
    case Kind::Materials: next.materials = *parse_material_override(c.arg), apply(next); break;
    case Kind::Tracer: next.tracer = c.arg, apply(next); break;
    case Kind::Layers:
      next.intermediate = c.arg == "bounces" ? SessionSettings::Intermediate::Bounces
                          : c.arg == "stage" ? SessionSettings::Intermediate::StageBuffers
                                             : SessionSettings::Intermediate::None;
      if (c.arg == "stage") next.stage_vertex = c.x;
      apply(next);
      break;
    case Kind::Open: next.scene_file = c.arg, apply(next); break;
    case Kind::ExportVtk: session_.export_vtk(c.arg); break;
    case Kind::Save: session_.save_image(c.arg, exposure_); break;
    case Kind::Screenshot: pending_screenshot_ = c.arg; break;
    case Kind::Quit: quit_ = true; break;
  }
}

// Runs script commands until one has to wait for a later frame.
void App::step_script() {
  while (next_command_ < script_.size() && !quit_ && pending_screenshot_.empty() && script_click_ == 0 &&
         script_drag_ == 0 && script_wheel_ == 0.0f && !script_moved_) {
    const ScriptCommand& c = script_[next_command_];
    try {
      if (c.kind == ScriptCommand::Kind::WaitSpp) {
        if (!waiting_since_) waiting_since_ = std::chrono::steady_clock::now();
        const bool other_done = !other_session_ || other_session_->wait_spp(c.x, 0.0);
        if (!session_.wait_spp(c.x, 0.05) || !other_done) {
          if (std::chrono::steady_clock::now() - *waiting_since_ > std::chrono::duration<double>(kScriptWaitSeconds))
            throw SystemError("waited " + std::to_string(static_cast<int>(kScriptWaitSeconds)) + " s for " +
                              std::to_string(c.x) + " spp");
          return;
        }
        waiting_since_.reset();
        session_.snapshot(snap_);  // the commands after it see the buffers it waited for
        texture_dirty_ = true;
      } else {
        in_command_ = true;
        run_command(c);
        in_command_ = false;
      }
    } catch (const std::exception& e) {
      in_command_ = false;
      err_ << "pathlab-debug: " << c.where << ": " << e.what() << "\n";
      exit_code_ = 2;
      quit_ = true;
      return;
    }
    ++next_command_;
  }
  if (!script_.empty() && next_command_ == script_.size() && script_click_ == 0 && script_drag_ == 0 &&
      script_wheel_ == 0.0f)
    quit_ = true;  // the script is over
}

void App::screenshot(const std::string& file) {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(w) * h * 3), flipped(rgb.size());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
  const std::size_t row = static_cast<std::size_t>(w) * 3;
  for (int y = 0; y < h; ++y)  // OpenGL's rows go bottom-up
    std::copy_n(&rgb[static_cast<std::size_t>(h - 1 - y) * row], row, &flipped[static_cast<std::size_t>(y) * row]);
  write_png_rgb8(file, w, h, flipped);
}

void App::frame() {
  if (script_.empty()) glfwWaitEventsTimeout(1.0 / 30.0);
  else glfwPollEvents();
  step_script();
  upload_textures();
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGuiIO& io = ImGui::GetIO();
  if (script_drag_ > 0) {  // after the backend has read the real mouse
    io.MousePos = script_drag_ == 1 ? drag_from_ : drag_to_;
    io.MouseDown[0] = script_drag_ < 3;
    script_mouse_ = io.MousePos;
  } else if (script_mouse_) {
    io.MousePos = *script_mouse_;
    io.MouseDown[0] = script_click_ == 1;
  }
  if (script_wheel_ != 0.0f) io.MouseWheel = script_wheel_;
  ImGui::NewFrame();
  draw_image();
  draw_panel();
  draw_events();
  ImGui::Render();
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  glViewport(0, 0, w, h);
  glClearColor(0.1f, 0.1f, 0.12f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  if (!pending_screenshot_.empty()) {
    try {
      screenshot(pending_screenshot_);
    } catch (const std::exception& e) {
      err_ << "pathlab-debug: " << e.what() << "\n";
      exit_code_ = 2;
      quit_ = true;
    }
    pending_screenshot_.clear();
  }
  if (script_click_ > 0) script_click_ = script_click_ == 1 ? 2 : 0;  // down one frame, then up
  if (script_drag_ > 0) script_drag_ = script_drag_ == 3 ? 0 : script_drag_ + 1;
  script_wheel_ = 0.0f;
  script_moved_ = false;
  const bool closing = quit_ || glfwWindowShouldClose(window_);
  if (closing && !options_.screenshot.empty()) {
    try {
      screenshot(options_.screenshot);
    } catch (const std::exception& e) {
      err_ << "pathlab-debug: " << e.what() << "\n";
      exit_code_ = 2;
    }
  }
  glfwSwapBuffers(window_);
}

int App::run() {
  if (!open_window()) {
    err_ << "pathlab-debug: cannot open a window (" << (g_glfw_error.empty() ? "no display?" : g_glfw_error)
         << "); on a machine without a display run it under xvfb-run -a\n";
    return 3;
  }
  while (!quit_ && !glfwWindowShouldClose(window_)) frame();
  return exit_code_;
}

}  // namespace

int run_app(const AppOptions& options, std::ostream& err) {
  try {
    App app(options, err);
    return app.run();
  } catch (const InputError& e) {
    err << "pathlab-debug: " << e.what() << "\n";
    return 2;
  } catch (const SystemError& e) {
    err << "pathlab-debug: " << e.what() << "\n";
    return 3;
  }
}

}  // namespace pathlab::debug
