#include "analytic-scenes/expected_image.h"

#include "core/parallel.h"

#include <algorithm>
#include <cmath>

namespace pathlab {
namespace {

// An edge's image on the film (pixels): the segment p-q, and how far the
// edge may stray from it (the curve's sagitta, float rounding of the rays).
struct FilmEdge {
  glm::dvec2 p, q;
  double margin;
};

// Film position of view direction v (relative to the eye, in front of it),
// inverting Camera::generate_ray.
glm::dvec2 to_film(const Camera::Plane& c, const FilmDesc& film, const dvec3& v) {
  const double f = glm::dot(v, dvec3(c.forward));
  const double sx = glm::dot(v, dvec3(c.right)) / f, sy = glm::dot(v, dvec3(c.up)) / f;
  return {(sx / (double(c.tan_half_fov) * c.aspect) + 1.0) * 0.5 * film.width,
          (1.0 - sy / double(c.tan_half_fov)) * 0.5 * film.height};
}

double distance_to_segment(const glm::dvec2& x, const glm::dvec2& p, const glm::dvec2& q) {
  const glm::dvec2 d = q - p;
  const double len2 = glm::dot(d, d);
  const double t = len2 > 0.0 ? std::clamp(glm::dot(x - p, d) / len2, 0.0, 1.0) : 0.0;
  return glm::length(x - (p + t * d));
}

// Float rounding in generate_ray and the models' float inputs move an edge
// by far less than this (pixels).
constexpr double kRoundingMargin = 1e-4;

std::vector<FilmEdge> project_edges(const EdgeList& edges, const Camera& camera, const FilmDesc& film) {
  const Camera::Plane c = camera.plane();
  const dvec3 fwd(c.forward);
  std::vector<FilmEdge> out;
  for (const EdgeArc& e : edges.arcs()) {
    // Clip to the half-space in front of the eye (f > eps |v|): what lies
    // behind is not on the film.
    dvec3 a = e.a, b = e.b;
    const double fa = glm::dot(a, fwd) - 1e-9 * glm::length(a), fb = glm::dot(b, fwd) - 1e-9 * glm::length(b);
    if (fa <= 0.0 && fb <= 0.0) continue;
    if (fa <= 0.0) a = a + (b - a) * (fa / (fa - fb)) + 1e-6 * (b - a);
    if (fb <= 0.0) b = b + (a - b) * (fb / (fb - fa)) + 1e-6 * (a - b);
    FilmEdge fe{to_film(c, film, a), to_film(c, film, b), kRoundingMargin};
    if (e.mid) {
      // The curve bulges at most about its bulge halfway (a short arc of a
      // smooth curve lies within a parabola of its chord); twice that.
      const bool clipped = a != e.a || b != e.b;
      const double fm = glm::dot(*e.mid, fwd);
      fe.margin += (!clipped && fm > 0.0) ? 2.0 * distance_to_segment(to_film(c, film, *e.mid), fe.p, fe.q) : 1.0;
    }
    if (std::isfinite(fe.p.x) && std::isfinite(fe.p.y) && std::isfinite(fe.q.x) && std::isfinite(fe.q.y))
      out.push_back(fe);
  }
  return out;
}

// True if segment p-q meets the rectangle [x0, x1] x [y0, y1] (Liang-Barsky).
bool segment_meets_box(const glm::dvec2& p, const glm::dvec2& q, double x0, double y0, double x1, double y1) {
  double t0 = 0.0, t1 = 1.0;
  const glm::dvec2 d = q - p;
  const double pk[4] = {-d.x, d.x, -d.y, d.y};
  const double qk[4] = {p.x - x0, x1 - p.x, p.y - y0, y1 - p.y};
  for (int k = 0; k < 4; ++k) {
    if (pk[k] == 0.0) {
      if (qk[k] < 0.0) return false;
    } else {
      const double t = qk[k] / pk[k];
      if (pk[k] < 0.0) t0 = std::max(t0, t);
      else t1 = std::min(t1, t);
      if (t0 > t1) return false;
    }
  }
  return true;
}

// Cells crossed by an edge are halved down to this side (pixels).
constexpr double kFinestCell = 1.0 / 1024.0;

struct Sums {
  dvec3 wL{0.0}, w2L{0.0}, w2L2{0.0}, edge_error{0.0};
  double w = 0.0, w2 = 0.0;
};

constexpr int kFirstGrid = 4;  // the first grid's cells per pixel unit

// The film's cells of side 1/kFirstGrid, each the root of a quadtree that
// outlives the grids of the doubling: at grid n a cell is split if it is
// larger than 1/n, or if an edge (widened by its margin) meets it and it is
// larger than kFinestCell; every other cell counts its midpoint. A cell an
// edge meets is split on every grid alike, so its subtree - the cells along
// the edges, their midpoints, the finest cells' corners - is built and
// evaluated once, before any pixel is integrated, and read by every grid of
// every pixel whose footprint holds it (the tent's footprints overlap: each
// cell lies in up to four). Only the cells no edge meets are evaluated anew
// per grid (a midpoint grid of 1/n is not nested in one of 1/(2n)). The
// footprints' corners (integers for the box, half-integers or the image's
// border for the tent) lie on the roots' grid.
class CellTree {
 public:
  struct Cell {
    double x = 0, y = 0, h = 0;  // corner and side (pixels)
    bool crossed = false;        // an edge meets it
    vec3 mid{0.0f};              // radiance at the midpoint (cells not split because of an edge)
    vec3 lo{0.0f}, hi{0.0f};     // finest cells an edge meets: the range over corners and midpoint
    std::vector<Cell> children;  // cells an edge meets
  };

  CellTree(const AnalyticModel& model, const Camera& camera, const FilmDesc& film)
      : model_(model), camera_(camera), rw_(film.width * kFirstGrid), rh_(film.height * kFirstGrid),
        roots_(static_cast<std::size_t>(rw_) * static_cast<std::size_t>(rh_)) {}

  // Builds and evaluates the roots of film pixels [ux0, ux1) x [uy0, uy1);
  // parallel over their rows (each root is written by one thread only).
  void build(const std::vector<FilmEdge>& edges, int ux0, int uy0, int ux1, int uy1) {
    parallel_for(static_cast<std::size_t>(uy0), static_cast<std::size_t>(uy1), 1, [&](std::size_t r0, std::size_t r1) {
      std::vector<const FilmEdge*> near;
      for (int uy = static_cast<int>(r0); uy < static_cast<int>(r1); ++uy)
        for (int ux = ux0; ux < ux1; ++ux) {
          near.clear();
          for (const FilmEdge& e : edges)
            if (segment_meets_box(e.p, e.q, ux - e.margin, uy - e.margin, ux + 1 + e.margin, uy + 1 + e.margin))
              near.push_back(&e);
          const double h = 1.0 / kFirstGrid;
          for (int j = 0; j < kFirstGrid; ++j)
            for (int i = 0; i < kFirstGrid; ++i) {
              Cell& c = root(ux * kFirstGrid + i, uy * kFirstGrid + j);
              c.x = ux + i * h;
              c.y = uy + j * h;
              c.h = h;
              grow(c, near);
            }
        }
    });
  }

  const Cell& root(int rx, int ry) const {
    return roots_[static_cast<std::size_t>(ry) * static_cast<std::size_t>(rw_) + static_cast<std::size_t>(rx)];
  }
  dvec3 L(double x, double y) const {
    return dvec3(model_.radiance(camera_.generate_ray(vec2(static_cast<float>(x), static_cast<float>(y)), vec2(0.5f))));
  }

 private:
  Cell& root(int rx, int ry) {
    return roots_[static_cast<std::size_t>(ry) * static_cast<std::size_t>(rw_) + static_cast<std::size_t>(rx)];
  }

  // Splits c down along the edges among `candidates` that meet it and reads
  // every midpoint and finest corner the grids will need.
  void grow(Cell& c, const std::vector<const FilmEdge*>& candidates) const {
    std::vector<const FilmEdge*> near;
    for (const FilmEdge* e : candidates)
      if (segment_meets_box(e->p, e->q, c.x - e->margin, c.y - e->margin, c.x + c.h + e->margin, c.y + c.h + e->margin))
        near.push_back(e);
    c.crossed = !near.empty();
    const bool finest = c.h <= kFinestCell * 1.000001;
    if (c.crossed && !finest) {
      const double h = c.h / 2;
      c.children.resize(4);
      for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
          Cell& k = c.children[static_cast<std::size_t>(2 * j + i)];
          k.x = c.x + i * h;
          k.y = c.y + j * h;
          k.h = h;
          grow(k, near);
        }
      return;
    }
    const dvec3 m = L(c.x + c.h / 2, c.y + c.h / 2);
    c.mid = vec3(m);
    if (c.crossed) {
      dvec3 lo = m, hi = m;
      for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
          const dvec3 Lc = L(c.x + i * c.h, c.y + j * c.h);
          lo = glm::min(lo, Lc);
          hi = glm::max(hi, Lc);
        }
      c.lo = vec3(lo);
      c.hi = vec3(hi);
    }
  }

  const AnalyticModel& model_;
  const Camera& camera_;
  int rw_, rh_;
  std::vector<Cell> roots_;
};

// One pixel's footprint on the tree: the roots it holds, visited on grid n.
class PixelIntegrator {
 public:
  PixelIntegrator(const CellTree& tree, const FilmDesc& film, int px, int py)
      : tree_(tree), box_(film.filter == FilterKind::Box), cx_(px + 0.5), cy_(py + 0.5) {
    const double x0 = box_ ? px : std::max(0.0, px - 0.5);
    const double x1 = box_ ? px + 1.0 : std::min<double>(film.width, px + 1.5);
    const double y0 = box_ ? py : std::max(0.0, py - 0.5);
    const double y1 = box_ ? py + 1.0 : std::min<double>(film.height, py + 1.5);
    rx0_ = static_cast<int>(std::lround(x0 * kFirstGrid));
    rx1_ = static_cast<int>(std::lround(x1 * kFirstGrid));
    ry0_ = static_cast<int>(std::lround(y0 * kFirstGrid));
    ry1_ = static_cast<int>(std::lround(y1 * kFirstGrid));
  }

  // The midpoint rule on the grid of side 1/n (n a power of two, at least
  // kFirstGrid), refined along the edges as above.
  Sums integrate(int n) const {
    Sums s;
    for (int ry = ry0_; ry < ry1_; ++ry)
      for (int rx = rx0_; rx < rx1_; ++rx) visit(s, tree_.root(rx, ry), 1.0 / n);
    return s;
  }

 private:
  double weight(double x, double y) const {
    return box_ ? 1.0 : std::max(0.0, 1.0 - std::abs(x - cx_)) * std::max(0.0, 1.0 - std::abs(y - cy_));
  }
  static void add(Sums& s, double w, double area, const dvec3& Lm) {
    s.wL += w * area * Lm;
    s.w += w * area;
    s.w2 += w * w * area;
    s.w2L += w * w * area * Lm;
    s.w2L2 += w * w * area * Lm * Lm;
  }

  void visit(Sums& s, const CellTree::Cell& c, double grid) const {
    if (!c.children.empty()) {
      for (const CellTree::Cell& k : c.children) visit(s, k, grid);
      return;
    }
    if (!c.crossed && c.h > grid * 1.000001) {
      // No edge here: this grid's midpoints, read afresh.
      const int m = static_cast<int>(std::lround(c.h / grid));
      for (int j = 0; j < m; ++j)
        for (int i = 0; i < m; ++i) {
          const double xm = c.x + (i + 0.5) * grid, ym = c.y + (j + 0.5) * grid;
          add(s, weight(xm, ym), grid * grid, tree_.L(xm, ym));
        }
      return;
    }
    const double xm = c.x + c.h / 2, ym = c.y + c.h / 2, area = c.h * c.h;
    add(s, weight(xm, ym), area, dvec3(c.mid));
    if (c.crossed) {
      // An edge crosses this finest cell: the midpoint may stand on either
      // side of it, so the cell's share can be off by up to its area times
      // the spread of the radiance over it, read at its corners and
      // midpoint (a straight edge through the cell leaves corners on both
      // sides of it).
      s.edge_error += (weight(xm, ym) + 2.0 * c.h) * area * (dvec3(c.hi) - dvec3(c.lo));
    }
  }

  const CellTree& tree_;
  bool box_;
  double cx_, cy_;
  int rx0_ = 0, rx1_ = 0, ry0_ = 0, ry1_ = 0;
};

struct PixelIntegral {
  dvec3 mean, footprint_variance, edge_error;
};

PixelIntegral finish(const Sums& s) {
  const dvec3 m = s.wL / s.w;
  // Int w^2 (L - m)^2 dA / (Int w dA)^2, with the w2 sums already per unit area.
  const dvec3 spread = glm::max(s.w2L2 - 2.0 * m * s.w2L + m * m * s.w2, dvec3(0.0));
  return {m, spread / (s.w * s.w), s.edge_error / s.w};
}

// One pixel: the doubling from kFirstGrid until two grids agree.
ExpectedPixel integrate_pixel(const CellTree& tree, const FilmDesc& film, int x, int y) {
  const PixelIntegrator pixel(tree, film, x, y);
  PixelIntegral prev = finish(pixel.integrate(kFirstGrid)), cur = prev;
  dvec3 diff(0.0);
  for (int n = 2 * kFirstGrid; n <= 128; n *= 2) {
    cur = finish(pixel.integrate(n));
    diff = glm::abs(cur.mean - prev.mean);
    prev = cur;
    if (glm::all(glm::lessThanEqual(diff, 1e-5 * glm::abs(cur.mean) + 1e-12))) break;
  }
  // The last difference bounds the error of the smooth part (both grids
  // resolve the edges alike); the edge cells add their bound.
  return {vec3(cur.mean), vec3(diff + cur.edge_error), vec3(cur.footprint_variance)};
}

std::vector<FilmEdge> film_edges(const AnalyticModel& model, const Camera& camera, const FilmDesc& film) {
  EdgeList edge_list(dvec3(camera.desc().position));
  model.edges(edge_list);
  return project_edges(edge_list, camera, film);
}

}  // namespace

ExpectedImage expected_image(const AnalyticModel& model, const Camera& camera, const FilmDesc& film) {
  ExpectedImage out{Image(film.width, film.height), Image(film.width, film.height), Image(film.width, film.height)};
  CellTree tree(model, camera, film);
  tree.build(film_edges(model, camera, film), 0, 0, film.width, film.height);
  parallel_for(0, static_cast<std::size_t>(film.height), 1, [&](std::size_t y0, std::size_t y1) {
    for (int y = static_cast<int>(y0); y < static_cast<int>(y1); ++y)
      for (int x = 0; x < film.width; ++x) {
        const ExpectedPixel p = integrate_pixel(tree, film, x, y);
        out.mean.at(x, y) = p.mean;
        out.quadrature_error.at(x, y) = p.quadrature_error;
        out.footprint_variance.at(x, y) = p.footprint_variance;
      }
  });
  return out;
}

ExpectedPixel expected_pixel(const AnalyticModel& model, const Camera& camera, const FilmDesc& film, int x, int y) {
  CellTree tree(model, camera, film);
  // The pixels whose cells the footprint holds (the tent's reaches half a
  // pixel into each neighbour).
  const int r = film.filter == FilterKind::Box ? 0 : 1;
  tree.build(film_edges(model, camera, film), std::max(0, x - r), std::max(0, y - r), std::min(film.width, x + r + 1),
             std::min(film.height, y + r + 1));
  return integrate_pixel(tree, film, x, y);
}

}  // namespace pathlab
