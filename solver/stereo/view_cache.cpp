#include "solver/stereo/view_cache.h"

#include <algorithm>
#include <iterator>
#include <string>

#include <tbb/parallel_for.h>

#include "core/error.h"

namespace subflow::solver {

ViewCache::ViewCache(int first_frame, int frames, int cameras, int faces, int dof)
    : first_frame_(first_frame), frames_(frames), cameras_(cameras), faces_(faces), dof_(dof) {
  if (frames < 0 || cameras < 0 || faces < 0 || (dof != 1 && dof != 3))
    ThrowError("ViewCache", "sizes", "needs frames, cameras, faces ≥ 0 and dof 1 or 3");
  index_.assign(static_cast<std::size_t>(frames) * cameras * faces, -1);
}

const SampledView* ViewCache::Add(int frame, int camera, int face, const PatchStencil& stencil,
                                  const std::function<PatchView()>& make_view,
                                  std::vector<const double*> increments, const std::vector<int>& rows) {
  const int t = frame - first_frame_;
  if (t < 0 || t >= frames_ || camera < 0 || camera >= cameras_ || face < 0 || face >= faces_)
    ThrowError("ViewCache", "view", "frame " + std::to_string(frame) + ", camera " + std::to_string(camera) +
                                        ", face " + std::to_string(face) + " is outside the cache");
  int& index = index_[(static_cast<std::size_t>(t) * cameras_ + camera) * faces_ + face];
  if (index < 0) {
    auto entry = std::make_unique<Entry>();
    entry->view = make_view();
    entry->view.first_block = 0;
    entry->stencil = &stencil;
    entry->increments = std::move(increments);
    if (!ViewFitsStencil(entry->view, stencil) || entry->increments.size() != entry->view.basis.size())
      ThrowError("ViewCache", "view", "needs an image, a camera, one position per sample and one basis and "
                                      "one parameter block per support vertex");
    entry->sampled.intensities.setZero(stencil.rows());
    entry->sampled.jacobian.setZero(stencil.rows(), stencil.cols() * dof_);
    index = static_cast<int>(entries_.size());
    entries_.push_back(std::move(entry));
    sampled_ = sampled_jacobians_ = false;
  }
  Entry& entry = *entries_[index];
  for (int row : rows)
    if (row < 0 || row >= entry.stencil->rows()) ThrowError("ViewCache", "rows", "sample index out of range");
  std::vector<int> merged;
  std::set_union(entry.rows.begin(), entry.rows.end(), rows.begin(), rows.end(), std::back_inserter(merged));
  if (merged.size() != entry.rows.size()) {
    entry.rows = std::move(merged);
    sampled_ = sampled_jacobians_ = false;
  }
  return &entry.sampled;
}

void ViewCache::PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) {
  if (new_evaluation_point) sampled_ = sampled_jacobians_ = false;
  if (sampled_ && (sampled_jacobians_ || !evaluate_jacobians)) return;
  tbb::parallel_for(0, size(), [&](int i) {
    Entry& entry = *entries_[i];
    SampleView(entry.view, *entry.stencil, dof_, entry.increments.data(), &entry.sampled.intensities,
               evaluate_jacobians ? &entry.sampled.jacobian : nullptr, &entry.rows);
  });
  sampled_ = true;
  sampled_jacobians_ = evaluate_jacobians;
}

}  // namespace subflow::solver
