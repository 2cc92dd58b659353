// The expected image of an analytic scene: the model's radiance integrated
// over each pixel's footprint with the film's filter, exactly as the film
// weighs samples (box: uniform over the pixel; bilinear: the tent of radius
// one pixel, restricted to the image and renormalised, as the film only
// receives samples from inside the image).
#pragma once

#include "analytic-scenes/analytic_model.h"
#include "core/camera.h"
#include "core/image_io.h"

namespace pathlab {

struct ExpectedImage {
  Image mean;              // filter-weighted mean radiance per pixel
  Image quadrature_error;  // estimated |error| of that integral, per channel
  // Int w^2 (L - mean)^2 / (Int w)^2 over the footprint: the variance of the
  // pixel estimate with one sample per pixel that comes from where the
  // sample lands alone. A render with n samples per pixel has at least this
  // over n (law of total variance), whatever its estimator; check.h uses it
  // as a floor where the sample variance missed a rare part of the
  // footprint (an edge pixel whose samples all fell on one side).
  Image footprint_variance;
};

// Midpoint quadrature on an n x n grid per pixel unit, every cell that an
// edge of the model (AnalyticModel::edges) meets split down to 1/1024
// pixel, doubling n from 4 until two successive estimates agree to 1e-5
// (relative) or n = 128. The cells along the edges are the same on every
// grid and for every footprint that holds them: they are built and
// evaluated once per film and read by every grid of every pixel. The quadrature error is the last difference plus, per
// finest cell an edge crosses, its weight x area x the radiance's spread
// over its midpoint and corners (docs/analytic-scenes.md states the
// guarantee). Parallel over rows.
ExpectedImage expected_image(const AnalyticModel& model, const Camera& camera, const FilmDesc& film);

// One pixel of expected_image(), computed alone (the same integrator: for
// tests that look at one pixel of many camera poses).
struct ExpectedPixel {
  vec3 mean, quadrature_error, footprint_variance;
};
ExpectedPixel expected_pixel(const AnalyticModel& model, const Camera& camera, const FilmDesc& film, int x, int y);

}  // namespace pathlab
