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
// The events of a `trace-pixel --json` document (docs/trace-pixel-json.md),
// every field first_divergence compares: the camera's pixel and sample come
// from the header; a document by a build older than the rays' fields has
// no shadow or continuation rays, which stay zero (forget_rays() on the
// other side of a comparison). Materials are numbered by their name in `scene`. Throws
// InputError naming `what` and the event.
std::vector<PathEvent> path_events_from_json(const nlohmann::json& doc, const Scene& scene, const std::string& what);
// Whether the document records the rays (`ray` of light events, `next` of
// scatter events).
bool trace_records_rays(const nlohmann::json& doc);
// Zeroes every shadow and continuation ray, as a document without them reads.
void forget_rays(std::vector<PathEvent>& events);
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
