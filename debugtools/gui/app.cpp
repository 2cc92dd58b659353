// The pathlab-debug window. GLFW, OpenGL and Dear ImGui headers stay in this
// file; everything it shows comes from Session (session.h).
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
#include <cstdint>
#include <cstdio>
#include <ostream>
#include <utility>

namespace pathlab::debug {
namespace {

constexpr float kPanelWidth = 460.0f;
constexpr double kScriptWaitSeconds = 600.0;

std::string g_glfw_error;  // the last GLFW error, for messages
void glfw_error(int code, const char* text) { g_glfw_error = std::to_string(code) + " " + text; }

ImU32 colour(const unsigned char (&c)[4]) { return IM_COL32(c[0], c[1], c[2], c[3]); }

// A titled separator between the panel's sections.
void section(const char* title) {
  ImGui::Spacing();
  ImGui::Separator();
  ImGui::TextDisabled("%s", title);
}

class App {
 public:
  App(const AppOptions& options, std::ostream& err)
      : options_(options), err_(err), session_(options.session), ui_(options.session),
        view_(parse_view(options.view).value_or(View::Beauty)), exposure_(options.exposure) {
    if (!parse_view(options.view)) throw InputError("unknown view '" + options.view + "'");
    if (!options.script.empty()) script_ = load_script(options.script);
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
  void upload_texture();
  void draw_image();
  void draw_overlay(ImDrawList* dl) const;
  void draw_panel();
  void apply(const SessionSettings& next);
  void click(int x, int y);
  void screenshot(const std::string& file);
  void sync_ui();
  template <typename F>
  void act(const char* what, F&& f);

  const AppOptions& options_;
  std::ostream& err_;
  Session session_;
  SessionSettings ui_;     // what the panel edits
  RenderSettings shown_;   // strategy, depth, spp, seed as the panel shows them
  View view_;
  float exposure_;
  Snapshot snap_;
  bool texture_dirty_ = true;

  GLFWwindow* window_ = nullptr;
  GLuint texture_ = 0;
  int tex_w_ = 0, tex_h_ = 0;
  float scale_ = 1.0f;
  bool imgui_ready_ = false;

  std::optional<std::pair<int, int>> hover_;  // the pixel under the mouse (or the script's)
  // The script's mouse: a position in window coordinates and a click in
  // progress (1: the button goes down this frame, 2: it comes up), fed to
  // ImGui in place of the real mouse so that hover and click take the same
  // path as a person's.
  std::optional<ImVec2> script_mouse_;
  int script_click_ = 0;
  int retrace_sample_ = 0;
  std::string scene_path_, vtk_path_ = "out/path.vtp", save_path_ = "out/debug.exr";
  std::string status_;

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

void App::apply(const SessionSettings& next) {
  act("restart", [&] { session_.apply(next); });
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

// The window for the current scene: the image 1:1 (scaled down to fit
// 1600x1000) and the panel beside it. Sets scale_.
std::pair<int, int> App::window_size() {
  const Scene& sc = session_.scene();
  scale_ = std::min({1.0f, 1000.0f / static_cast<float>(sc.film.height),
                     (1600.0f - kPanelWidth) / static_cast<float>(sc.film.width)});
  return {static_cast<int>(static_cast<float>(sc.film.width) * scale_ + kPanelWidth),
          std::max(static_cast<int>(static_cast<float>(sc.film.height) * scale_), 720)};
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
  glGenTextures(1, &texture_);
  return true;
}

void App::close_window() {
  if (imgui_ready_) {
    if (texture_) glDeleteTextures(1, &texture_);
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    imgui_ready_ = false;
  }
  if (window_) glfwDestroyWindow(window_);
  window_ = nullptr;
  glfwTerminate();
}

void App::upload_texture() {
  const bool changed = session_.snapshot(snap_);
  if (!changed && !texture_dirty_) return;
  texture_dirty_ = false;
  if (snap_.width == 0) return;
  const std::vector<std::uint8_t> rgba = view_rgba(snap_, view_, exposure_);
  glBindTexture(GL_TEXTURE_2D, texture_);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);  // pixels stay pixels
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA, snap_.width, snap_.height, 0, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  tex_w_ = snap_.width;
  tex_h_ = snap_.height;
}

void App::draw_overlay(ImDrawList* dl) const {
  const auto& r = session_.current_retrace();
  if (!r || r->lines.empty()) return;
  const FilmProjection& proj = session_.projection();
  const auto screen = [&](vec2 f) { return ImVec2(f.x * scale_, f.y * scale_); };
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
  const ImVec2 size(static_cast<float>(tex_w_) * scale_, static_cast<float>(tex_h_) * scale_);
  ImDrawList* dl = ImGui::GetBackgroundDrawList();
  if (tex_w_ > 0)
    dl->AddImage(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(texture_)), ImVec2(0, 0), size);
  dl->PushClipRect(ImVec2(0, 0), size, false);
  draw_overlay(dl);
  dl->PopClipRect();

  // The mouse, unless a panel has it.
  const ImGuiIO& io = ImGui::GetIO();
  if (io.WantCaptureMouse) return;
  const ImVec2 m = io.MousePos;
  if (m.x >= 0 && m.y >= 0 && m.x < size.x && m.y < size.y) {
    const int x = static_cast<int>(m.x / scale_), y = static_cast<int>(m.y / scale_);
    hover_ = std::pair(x, y);
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left)) click(x, y);
  }
}

void App::draw_panel() {
  ImGui::SetNextWindowPos(ImVec2(static_cast<float>(tex_w_) * scale_, 0));
  ImGui::SetNextWindowSize(ImVec2(kPanelWidth, ImGui::GetIO().DisplaySize.y));
  ImGui::Begin("pathlab-debug", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
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
  if (ImGui::Button("Restart") || changed) apply(next);
  ImGui::Text("%d / %d spp  seed %llu  %.1f s", snap_.spp_done, snap_.spp_target,
              static_cast<unsigned long long>(snap_.seed), snap_.seconds);

  // Views.
  section("view");
  int v = static_cast<int>(view_);
  if (ImGui::Combo("buffer", &v, "beauty\0albedo\0shading normal\0depth\0material id\0variance\0path length\0NaN/Inf\0"))
    view_ = static_cast<View>(v), texture_dirty_ = true;
  if (ImGui::SliderFloat("exposure", &exposure_, -10.0f, 10.0f, "%.1f stops")) texture_dirty_ = true;

  // The pixel under the mouse.
  section("pixel");
  if (hover_) {
    const PixelReadout p = session_.readout(snap_, hover_->first, hover_->second);
    ImGui::Text("(%d, %d)  %u samples", p.x, p.y, p.samples);
    ImGui::Text("radiance   %.5g  %.5g  %.5g", static_cast<double>(p.radiance.x), static_cast<double>(p.radiance.y),
                static_cast<double>(p.radiance.z));
    ImGui::Text("std error  %.3g  %.3g  %.3g", static_cast<double>(p.std_error.x), static_cast<double>(p.std_error.y),
                static_cast<double>(p.std_error.z));
    ImGui::Text("path length %.2f   NaN/Inf samples %u", static_cast<double>(p.path_length), p.nonfinite);
  } else {
    ImGui::TextUnformatted("hover over the image");
  }

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
    if (!status_.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", status_.c_str());
    ImGui::BeginChild("events", ImVec2(0, 0), true, ImGuiWindowFlags_HorizontalScrollbar);
    for (const std::string& line : r->text) ImGui::TextUnformatted(line.c_str());
    ImGui::EndChild();
  } else {
    ImGui::TextUnformatted("click a pixel to replay its sample");
    if (!status_.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", status_.c_str());
  }
  ImGui::End();
}

void App::run_command(const ScriptCommand& c) {
  using Kind = ScriptCommand::Kind;
  SessionSettings next = session_.settings();
  switch (c.kind) {
    case Kind::WaitSpp: break;  // handled by step_script
    case Kind::Hover:
    case Kind::Click:
      if (c.x >= session_.scene().film.width || c.y >= session_.scene().film.height)
        throw InputError("pixel (" + std::to_string(c.x) + ", " + std::to_string(c.y) + ") is outside the image");
      // The centre of the pixel, where it is drawn.
      script_mouse_ = ImVec2((static_cast<float>(c.x) + 0.5f) * scale_, (static_cast<float>(c.y) + 0.5f) * scale_);
      if (c.kind == Kind::Click) script_click_ = 1;
      break;
    case Kind::Sample: retrace_sample_ = c.x; break;
    case Kind::View: view_ = *parse_view(c.arg), texture_dirty_ = true; break;
    case Kind::Exposure: exposure_ = c.value, texture_dirty_ = true; break;
    case Kind::Materials: next.materials = *parse_material_override(c.arg), apply(next); break;
    case Kind::Tracer: next.tracer = c.arg, apply(next); break;
    case Kind::Open: next.scene_file = c.arg, apply(next); break;
    case Kind::ExportVtk: session_.export_vtk(c.arg); break;
    case Kind::Save: session_.save_image(c.arg, exposure_); break;
    case Kind::Screenshot: pending_screenshot_ = c.arg; break;
    case Kind::Quit: quit_ = true; break;
  }
}

// Runs script commands until one has to wait for a later frame.
void App::step_script() {
  while (next_command_ < script_.size() && !quit_ && pending_screenshot_.empty() && script_click_ == 0) {
    const ScriptCommand& c = script_[next_command_];
    try {
      if (c.kind == ScriptCommand::Kind::WaitSpp) {
        if (!waiting_since_) waiting_since_ = std::chrono::steady_clock::now();
        if (!session_.wait_spp(c.x, 0.05)) {
          if (std::chrono::steady_clock::now() - *waiting_since_ > std::chrono::duration<double>(kScriptWaitSeconds))
            throw SystemError("waited " + std::to_string(static_cast<int>(kScriptWaitSeconds)) + " s for " +
                              std::to_string(c.x) + " spp");
          return;
        }
        waiting_since_.reset();
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
  if (!script_.empty() && next_command_ == script_.size()) quit_ = true;  // the script is over
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
  upload_texture();
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  if (script_mouse_) {  // after the backend has read the real mouse
    ImGuiIO& io = ImGui::GetIO();
    io.MousePos = *script_mouse_;
    io.MouseDown[0] = script_click_ == 1;
  }
  ImGui::NewFrame();
  draw_image();
  draw_panel();
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
