// Evidence voxels in the working volume (method §4.1, eq. 23 integrated over footprints):
// silhouettes → occupancy of a voxel grid → 3D morphology → connected components.
//
// Grid: MakeVoxelGrid covers the working volume (Bounds) with cubic voxels; sample
// (i, j, k) of the geometry::ScalarVolume is the voxel's centre (see scalar_volume.h).
// The grid is NOT padded: an object that reaches the bounds touches the grid's border
// (reported as a warning); an iso-surface extractor should pad with empty voxels.
//
// Carving, per voxel V and camera k:
//   footprint  the bounding box of the 8 projected corners of V, projected with
//              Camera::Project — WITH lens distortion, because silhouettes are in raw
//              image coordinates (vision/silhouettes.h);
//   k sees V   when all 8 corners are in front of the camera (depth > 0; with distortion,
//              also within the image grown by its size before distortion, where the
//              polynomial cannot fold back) and the footprint lies inside the image
//              [−½, w − ½) × [−½, h − ½) (pixel (0, 0) = centre of the top-left pixel);
//   evidence   e_k(V) = mean of the camera's evidence image over the pixels whose centres
//              lie in the footprint grown by footprint_margin pixels on each side and
//              clipped to the image (summed-area table, cv::integral, O(1) per voxel;
//              along an axis where that box contains no pixel centre, the pixel row /
//              column nearest its centre);
//   hit / miss e_k(V) ≥ evidence_threshold / below it.
// V is occupied ⇔ hits(V) ≥ min_cameras and misses(V) ≤ max_misses. So a voxel is carved
// only by the cameras that see it (a partial rig works), and a voxel seen by fewer than
// min_cameras cameras is NOT occupied: one view alone cannot locate anything along its
// rays, so such voxels (e.g. the corners of the volume outside most frusta) stay empty.
//
// The defaults make the hull CONSERVATIVE: it contains the true visual hull, and so the
// object. A voxel is kept when its cube's projection (inside the footprint) reaches the
// silhouette at all (evidence_threshold small), and the ½-pixel margin covers the
// sampling of silhouettes at pixel centres (a contour is known to ±½ pixel). Hence every
// voxel whose centre lies in the visual hull is occupied, the iso-surface at ½ of the
// occupancy (half-way between occupied and empty centres) encloses the hull, and it lies
// outside the hull by at most ~(√3/2 + ½) voxel + 1 pixel. evidence_threshold = 0.5 and
// no margin would instead centre the boundary on the silhouette cones (unbiased, but
// about half of the surface would then fall inside the object by up to half a voxel).
//
// Cleaning (in this order): closing then opening with a (2r + 1)³ box, keep connected
// components with ≥ min_component_fraction × the largest one's voxels, fill interior
// cavities (vision/voxel_morphology.h).
//
// Bad input: a camera that sees nothing of the volume or whose silhouette is empty (it
// would carve away every voxel it sees) is excluded with a warning naming it (and the
// frame); when no camera remains, or the remaining ones cannot reach min_cameras, that is
// an error. An object touching the border of the volume gives a warning naming the frame
// and the side(s). Warnings are logged (spdlog) and returned in CarvingResult::warnings.
#pragma once

#include <array>
#include <cstddef>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "geometry/scalar_volume.h"
#include "vision/camera.h"
#include "vision/silhouettes.h"
#include "vision/voxel_projection.h"  // ProjectOccupancy, SilhouetteIoU
#include "vision/working_volume.h"

namespace subflow::vision {

class Dataset;

struct VoxelCarvingOptions {
  // Voxels along the longest axis of the working volume; 0 = automatic: a voxel projects
  // to about pixels_per_voxel pixels in the finest camera that sees the volume's centre,
  // capped at max_auto_resolution.
  int resolution = 0;
  // Target footprint (pixels) of one voxel edge for the automatic resolution.
  double pixels_per_voxel = 2.0;
  // Cap of the automatic resolution (memory and time grow with its cube).
  int max_auto_resolution = 160;
  // Shape initialization computes the evidence (silhouettes, estimated background) on
  // images reduced so that a voxel spans at most this many pixels at the volume's centre
  // (vision/working_scale.h: EvidenceScale); never enlarged. A voxel's evidence is the
  // mean over its footprint, so finer images only cost time: an HD take whose voxels span
  // 13–15 px (the 160-voxel cap over a room-sized volume) is carved from ~1/4-size images.
  // 0 = the stored size.
  double max_pixels_per_voxel = 4.0;
  // A voxel must be seen AND supported (evidence ≥ threshold) by at least this many
  // cameras to be occupied. 2 = the fewest that triangulate; raise it on dense rigs.
  int min_cameras = 2;
  // Cameras that see a voxel but have too little evidence there, tolerated before the
  // voxel is carved. −1 = automatic: 0 (strict visual hull) when every used camera's
  // evidence is a mask or a background difference, 1 when some come from motion (motion
  // silhouettes miss bites where the object moves little or has no texture).
  // Background silhouettes match the masks (mean IoU 0.98–0.99 on the synth scenes and
  // ../shared/data/blob), and tolerating a miss there fattens the hull by a voxel on a
  // ring of cameras (blob: accuracy P90 6.3 mm instead of 3.0, completeness 34 % instead of 96 %).
  int max_misses = -1;
  // Fraction of a footprint's pixels that must be object for a camera to support a voxel.
  // Small = conservative hull (see the file comment); 0.1 ignores a stray pixel or two.
  double evidence_threshold = 0.1;
  // Pixels added on each side of a footprint for the evidence mean (not for "sees"):
  // ½ covers the pixel-centre sampling of silhouettes.
  double footprint_margin = 0.5;
  // Radius (voxels) of the closing, then of the opening (box (2r + 1)³); 0 = skip. These
  // are the radii on the automatic grid; ResolveCarvingOptions narrows them on a coarser one.
  // −1 = automatic: 0 when every used camera's evidence is the object's outline (a mask, or
  // a plain backdrop's difference: Silhouette::outline), 1 otherwise. The
  // cleaning is for measured silhouettes (background differences, motion, stills: specks,
  // bites); on masks it only removes thin parts (a 3 mm ear plate on 2.8 mm voxels) and
  // bridges narrow gaps (between legs), and without it the refined surfaces of the mask
  // scenes are as accurate or better and more complete (docs/shape.md, "Cleaning the hull
  // only where the silhouettes are measured").
  int closing_radius = -1;
  int opening_radius = -1;
  // Connectivity of occupied voxels for components (6 or 26); empty space uses the other.
  int connectivity = 26;
  // Components with fewer voxels than this fraction of the largest are removed.
  double min_component_fraction = 0.1;
  // Fill interior cavities (empty regions not connected to the volume's border).
  bool fill_cavities = true;
  // Compute CameraCarvingReport::silhouette_iou (projects the surface voxels of the
  // result into every used camera; about +15 % time at 128³ on the blob dataset).
  bool compute_silhouette_iou = true;
  // Worker threads (TBB); 0 = all available, 1 = serial (e.g. for a benchmark baseline).
  int threads = 0;

  // Throws subflow::Error naming the field when an option is out of range.
  void Check() const;
};

struct CameraCarvingReport {
  std::string name;
  EvidenceSource source = EvidenceSource::kMask;  // where the camera's silhouette came from
  bool used = false;       // took part in the carving
  std::string excluded;    // why not, "" when used
  int object_pixels = 0;   // pixels of the silhouette
  // The threshold that made the silhouette from its measure (Silhouette::threshold): 0.5
  // for masks, else the automatic (Otsu / triangle) or given value, in the measure's units.
  double threshold = 0.5;
  // |P ∩ S| / |P ∪ S| over the image, P = the projection of the occupied voxels' cubes
  // (ProjectOccupancy), S = this camera's silhouette; NaN for unused cameras or when not
  // computed. The cubes' staircase reaches a little beyond the iso-surface at ½, and the
  // conservative hull beyond the silhouette cones, so expect ≈ 0.9 rather than 1.
  double silhouette_iou = std::numeric_limits<double>::quiet_NaN();
};

struct CarvingResult {
  int frame = 0;
  geometry::ScalarVolume occupancy;  // 0 / 1 per voxel, after cleaning
  int resolution = 0;                // voxels along the longest axis
  int max_misses = 0;                // the value used (after "automatic")
  int closing_radius = 0, opening_radius = 0;  // the radii used (voxels, after "automatic")
  std::size_t carved_voxels = 0;     // occupied straight after carving
  std::size_t occupied_voxels = 0;   // occupied after cleaning
  int components_found = 0, components_kept = 0;
  std::size_t cavity_voxels_filled = 0;
  // Occupied voxels on the faces −x, +x, −y, +y, −z, +z of the grid (object leaving the bounds).
  std::array<std::size_t, 6> border_voxels{};
  std::vector<CameraCarvingReport> cameras;  // one per camera, in input order
  double mean_silhouette_iou = std::numeric_limits<double>::quiet_NaN();  // over used cameras
  std::vector<std::string> warnings;
};

// The grid's sides in border_voxels order: "-x", "+x", "-y", "+y", "-z", "+z".
extern const char* const kBorderSides[6];
// One line per side that the object touches in any of `frames` (the carvings of a take):
// in how many frames, the first and last of them, and the most voxels in one frame.
// CarveVoxels records "frame F: the object touches the … side" in its result's warnings
// but logs it at debug level only: a take has it in most frames, so shape initialization
// logs these lines instead.
std::vector<std::string> SummarizeBorderContacts(const std::vector<const CarvingResult*>& frames);

// The voxel count along the longest axis: options.resolution when > 0, else automatic:
// spacing = pixels_per_voxel / max_k (f_k / depth_k(centre)) over the cameras that see
// the volume's centre (f_k = (fx + fy) / 2), clamped to [8, max_auto_resolution]; the
// cap when no camera sees the centre.
int ChooseResolution(const std::vector<Camera>& cameras, const Bounds& bounds,
                     const VoxelCarvingOptions& options);

// The automatic grid's spacing before its cap: pixels_per_voxel / max_k (f_k / depth_k(centre))
// as above; 0 when no camera sees the volume's centre.
double AutomaticVoxelSpacing(const std::vector<Camera>& cameras, const Bounds& bounds,
                             const VoxelCarvingOptions& options);

// The options with which the images of `cameras` (the STORED images, before any reduction
// for the evidence) are carved: the resolution fixed (ChooseResolution), and the closing and
// opening radii narrowed where that grid is coarser than the automatic one (the cap over a
// large volume, or a coarse `resolution`):
//     r ← min(r, ⌊r · s_auto / s + ½⌋),   s_auto = AutomaticVoxelSpacing, s = the grid's spacing,
// so that the morphology's box never spans more image pixels than on the automatic grid.
// Why: the closing and the opening clean what silhouette noise leaves in the carving —
// specks, pinholes, slivers a few pixels wide — and their box is sized for voxels of
// pixels_per_voxel pixels. On a coarser grid a voxel's footprint already averages many
// pixels (a speck must cover evidence_threshold of it to count), and the same box spans
// parts of the subject instead: on the pose2sim take (a room-sized volume, the 160-voxel
// cap, voxels of 2.7 cm spanning ~11 pixels of the stored images) the 3-voxel opening
// removed shins, feet and forearms — the 4–8 cm parts of a person — in every frame.
// Radii are unchanged on the automatic grid and on finer ones, and when no camera sees
// the volume's centre.
VoxelCarvingOptions ResolveCarvingOptions(const std::vector<Camera>& cameras, const Bounds& bounds,
                                          const VoxelCarvingOptions& options);

// An empty grid of cubic voxels of edge L / resolution (L = the longest side of
// `bounds`), ceil(size / spacing) voxels per axis, centred on the bounds.
geometry::ScalarVolume MakeVoxelGrid(const Bounds& bounds, int resolution);

// The corner pixels of the distorted cameras, kept between the frames of a take carved in
// one grid by one rig: a distorted camera's corner costs a Camera::Project (a pinhole
// camera's a multiply-add, not kept), the same for every frame. Within a byte budget;
// cameras past it are projected per frame. Kept values are ProjectCorner's, so a carving
// is the same with the cache as without it. One rig: a camera index must name the same
// camera in every call.
class CornerPixelCache {
 public:
  explicit CornerPixelCache(std::size_t budget_bytes = std::size_t{256} << 20) : budget_(budget_bytes) {}
  // The corners of camera `index` (`camera`) in `grid`, projected on the first call for
  // this grid; null for a camera without distortion or past the budget. Not thread-safe.
  const GridCornerPixels* Get(int index, const Camera& camera, const geometry::ScalarVolume& grid);

 private:
  std::vector<double> grid_;  // origin, spacing and sizes of the grid the corners are of
  std::map<int, GridCornerPixels> cameras_;  // by camera index
  std::size_t bytes_ = 0;
  const std::size_t budget_;
};

// Carves, cleans and measures (see the file comment). silhouettes[k] belongs to
// cameras[k] and must have its size. `frame` only labels messages and the result.
// `corners` (may be null): the distorted cameras' corner pixels, kept across frames.
CarvingResult CarveVoxels(const std::vector<Camera>& cameras,
                          const std::vector<Silhouette>& silhouettes, const Bounds& bounds,
                          const VoxelCarvingOptions& options, int frame = 0, CornerPixelCache* corners = nullptr);

// ComputeSilhouettes + CarveVoxels on the dataset's cameras and bounds at one frame.
CarvingResult CarveFrame(const Dataset& dataset, int frame,
                         const SilhouetteOptions& silhouette_options = {},
                         const VoxelCarvingOptions& carving_options = {});

}  // namespace subflow::vision
