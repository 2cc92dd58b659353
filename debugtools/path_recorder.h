// Records the events of one path (a PathObserver) and writes them out as a
// readable trace or as stable JSON (docs/trace-pixel-json.md).
#pragma once

#include "core/path_observer.h"
#include "core/scene.h"

#include <nlohmann/json.hpp>

#include <string>
#include <variant>
#include <vector>

namespace pathlab {

using PathEvent = std::variant<CameraEvent, HitEvent, EscapeEvent, LightEvent, ScatterEvent, EndEvent>;

class PathRecorder final : public PathObserver {
 public:
  void on_camera(const CameraEvent& e) override { events_.emplace_back(e); }
  void on_hit(const HitEvent& e) override { events_.emplace_back(e); }
  void on_escape(const EscapeEvent& e) override { events_.emplace_back(e); }
  void on_light(const LightEvent& e) override { events_.emplace_back(e); }
  void on_scatter(const ScatterEvent& e) override { events_.emplace_back(e); }
  void on_end(const EndEvent& e) override { events_.emplace_back(e); }
  void on_result(const Spectrum& L) override { result_ = L; }

  const std::vector<PathEvent>& events() const { return events_; }
  const Spectrum& result() const { return result_; }

 private:
  std::vector<PathEvent> events_;
  Spectrum result_{0.0f};
};

// Identifies the replayed sample in the output.
struct TraceHeader {
  std::string scene;      // file, or "<built-in cornell>"
  std::string tracer;
  std::uint32_t x = 0, y = 0, sample = 0;
  RenderSettings settings;
  int width = 0, height = 0;  // the film: pixel numbering and camera rays depend on it
  std::string command_line{};  // the command that produced the trace, if any
};

// What the film receives for the recorded sample: its radiance after the
// firefly clamp of `settings` (clamp_radiance, core/render.h), the same
// function and bits as a render's.
Spectrum film_radiance(const TraceHeader& header, const PathRecorder& path);

// The JSON document of a recorded path (format version 1).
nlohmann::json path_to_json(const TraceHeader& header, const PathRecorder& path, const Scene& scene);
// One event as text (one line, two for a hit with emission).
std::string event_to_text(const PathEvent& event, const Scene& scene);
// The header line of a listing.
std::string trace_header_text(const TraceHeader& header);
// "radiance (r, g, b)" and, if the clamp changed it, "film (r, g, b)
// (clamped to C ...)", each line starting with `who`.
std::string result_text(const TraceHeader& header, const PathRecorder& path, const char* who);
// A human-readable listing, one event per line or two.
std::string path_to_text(const TraceHeader& header, const PathRecorder& path, const Scene& scene);

}  // namespace pathlab
