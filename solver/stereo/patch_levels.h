// How deep the stereo refinement goes, patch by patch (method §4: "the refinement can be
// locally controlled by the magnitude of the detail coefficients. If they are small in a
// region of the mesh, there is no need for further subdivision"), bounded by the images'
// resolution: a correlation window of about 4.5 × 4.5 px needs min_patch_area pixels² of
// texture.
//
// The projected area of a patch (face of level ℓ) is taken as that of its base face,
// divided by 4^ℓ (Loop subdivision splits every face in four; the descendants of base face
// f0 on level ℓ are the faces f with f >> 2ℓ = f0), the base face's area being the largest
// over the cameras facing it, at one frame.
//   median level  the finest level whose MEDIAN patch still covers min_patch_area: every
//                 patch is refined down to it (where its parent moved);
//   deeper        with per_patch_levels, patches below the median level are refined where
//                 their parent moved and they still cover min_patch_area themselves (large
//                 base faces, close or frontal views), down to the deepest level any patch
//                 reaches;
//   large details with per_patch_levels, patches below min_patch_area are still refined
//                 where their parent's corners moved by a large part of the parent's edge
//                 (stereo_refinement.h: detail_threshold — a hollow or a thin part the
//                 coarser level could not follow), as long as they cover
//                 min_detail_patch_area: the NCC of such a patch is noisy alone, but each
//                 vertex's increment is shared by the ~6 patches around it and smoothed
//                 by the membrane term, so the unknowns still see ≥ 6× that area.
#pragma once

#include <cmath>
#include <vector>

#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"
#include "vision/camera.h"

namespace subflow::solver {

class PatchLevels {
 public:
  // Areas of the base faces of the surface of `finest_control` (#V(n)×3) in `cameras`.
  PatchLevels(const geometry::LoopHierarchy& hierarchy, const geometry::Positions& finest_control,
              const std::vector<vision::Camera>& cameras, double min_patch_area, bool per_patch_levels,
              double min_detail_patch_area = 0.0);

  // The median level (0 when no base face is seen), at most the hierarchy's finest.
  int median_level() const { return median_level_; }
  // The finest level refined: the median level, or with per_patch_levels the deepest
  // level at which some patch covers min_patch_area (min_detail_patch_area when smaller
  // and > 0: patches with large details may go there).
  int finest_level() const { return finest_level_; }
  // Whether face `face` of `level` is fine enough to be refined by the resolution rule
  // (every face down to the median level; below it, its own area).
  bool Resolved(int level, int face) const;
  // Whether it is fine enough to be refined where its parent had large details: Resolved,
  // or, with per_patch_levels, its own area covers min_detail_patch_area.
  bool ResolvedForDetail(int level, int face) const;
  // Per base face: its largest projected area, pixels² (0 = unseen).
  const std::vector<double>& base_areas() const { return base_area_; }

 private:
  std::vector<double> base_area_;  // per base face, pixels² (0 = unseen)
  double min_area_ = 0, min_detail_area_ = 0;
  double Area(int level, int face) const { return std::ldexp(base_area_.at(face >> (2 * level)), -2 * level); }
  bool per_patch_ = false;
  int median_level_ = 0, finest_level_ = 0;
};

}  // namespace subflow::solver
