#include "prizma/render/volume_inspection.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace prizma::render {

namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// 12 345 678 → "12 345 678": voxel counts of a large volume stay readable.
std::string count(std::uint64_t n) {
  std::string digits = std::to_string(n), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ' ';
    out += digits[i];
  }
  return out;
}

std::string share(std::uint64_t n, std::uint64_t of) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f %%", of == 0 ? 0.0 : 100.0 * static_cast<double>(n) / static_cast<double>(of));
  return buf;
}

const char* kind_of(const InspectedVolume& in) {
  const std::string& s = in.volume.source;
  if (s.size() >= 4 && (s.rfind(".nii") == s.size() - 4 || s.rfind(".nii.gz") == s.size() - 7)) return "NIfTI";
  if (s.size() >= 4 && s.rfind(".vdb") == s.size() - 4) return "OpenVDB";
  if (s.size() >= 4 && s.rfind(".raw") == s.size() - 4) return "raw";
  return "procedural";
}

}  // namespace

VolumeStatistics volume_statistics(const InspectedVolume& in, int histogram_bins) {
  const Volume& vol = in.volume;
  const std::vector<MaterialRule>& rules = in.transfer.rules;
  VolumeStatistics st;
  st.voxels = vol.values.size();
  st.rule_voxels.assign(rules.size(), 0);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, sum = 0.0;
  double nz_lo = lo, nz_hi = hi;
  for (const float f : vol.values) {
    const double v = f;
    if (!std::isfinite(v)) {
      ++st.non_finite;
      ++st.unassigned;  // a non-finite value is empty space for the renderer
      continue;
    }
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    sum += v;
    if (v == 0.0) {
      ++st.zeros;
    } else {
      nz_lo = std::min(nz_lo, v);
      nz_hi = std::max(nz_hi, v);
    }
    // The renderer's classification of a voxel centre: the first rule whose range holds the value.
    bool taken = false;
    for (std::size_t r = 0; r < rules.size() && !taken; ++r) {
      if (v >= rules[r].value_lo && v <= rules[r].value_hi) {
        ++st.rule_voxels[r];
        taken = true;
      }
    }
    if (!taken) ++st.unassigned;
  }
  const std::uint64_t finite = st.voxels - st.non_finite;
  if (finite > 0) {
    st.min = lo;
    st.max = hi;
    st.mean = sum / static_cast<double>(finite);
  }
  // The histogram of the values that are not exactly 0, over their own range.
  st.counts.assign(static_cast<std::size_t>(std::max(histogram_bins, 1)), 0);
  if (finite > st.zeros) {
    st.histogram_lo = nz_lo;
    st.histogram_hi = nz_hi;
    const double width = nz_hi > nz_lo ? (nz_hi - nz_lo) / static_cast<double>(st.counts.size()) : 1.0;
    for (const float f : vol.values) {
      const double v = f;
      if (!std::isfinite(v) || v == 0.0) continue;
      const auto k = std::min(static_cast<std::size_t>((v - nz_lo) / width), st.counts.size() - 1);
      ++st.counts[k];
    }
  }
  return st;
}

std::string inspection_report(const InspectedVolume& in, const VolumeStatistics& st) {
  const Volume& vol = in.volume;
  std::ostringstream out;
  out << (in.from_scene ? "scene       " + in.input + "\n" : "");
  out << "volume      " << vol.source << " (" << kind_of(in) << "): " << vol.dims[0] << " × " << vol.dims[1] << " × "
      << vol.dims[2] << " voxels (" << count(st.voxels) << ")\n";
  out << "voxel size  " << num(vol.spacing[0]) << " × " << num(vol.spacing[1]) << " × " << num(vol.spacing[2])
      << (std::string(kind_of(in)) == "NIfTI" ? " mm" : " (the file's units)") << "\n";
  // The box in scene units: the physical extent scaled so that its largest side is 1 (scene-format.md).
  double extent[3], largest = 0.0;
  for (int a = 0; a < 3; ++a) largest = std::max(largest, extent[a] = vol.dims[a] * vol.spacing[a]);
  out << "box         " << num(extent[0] / largest) << " × " << num(extent[1] / largest) << " × " << num(extent[2] / largest)
      << " scene units, centred at the origin (x, y, z; largest side 1)\n";
  out << "orientation " << (vol.orientation.empty() ? "file axes as +x, +y, +z" : vol.orientation) << "\n";
  for (const std::string& w : vol.warnings) out << "warning     " << w << "\n";
  out << "values      min " << num(st.min) << ", max " << num(st.max) << ", mean " << num(st.mean) << "; "
      << count(st.zeros) << " exactly 0 (" << share(st.zeros, st.voxels) << ")";
  if (st.non_finite > 0) out << ", " << count(st.non_finite) << " not finite (empty space)";
  out << "\n";
  if (in.from_scene) {
    out << "normalised  [0, 1] ← [" << num(in.normalisation.min) << ", " << num(in.normalisation.max) << "] ("
        << (in.normalisation_given ? "the scene's normalisation" : "\"auto\": the values' range") << ")\n";
  }
  // The histogram: bars in proportion to the fullest bin, voxels and share of all voxels.
  const std::uint64_t fullest = *std::max_element(st.counts.begin(), st.counts.end());
  out << "histogram   " << st.counts.size() << " bins over [" << num(st.histogram_lo) << ", " << num(st.histogram_hi)
      << "], values ≠ 0 (voxels, share of all):\n";
  const double width = (st.histogram_hi - st.histogram_lo) / static_cast<double>(st.counts.size());
  for (std::size_t k = 0; k < st.counts.size(); ++k) {
    const int bar = fullest == 0 ? 0 : static_cast<int>(std::lround(40.0 * static_cast<double>(st.counts[k]) / static_cast<double>(fullest)));
    char range[64];
    std::snprintf(range, sizeof range, "  [%10s, %10s%s", num(st.histogram_lo + width * static_cast<double>(k)).c_str(),
                  num(st.histogram_lo + width * static_cast<double>(k + 1)).c_str(), k + 1 == st.counts.size() ? "]" : ")");
    std::string bars;
    for (int b = 0; b < bar; ++b) bars += "█";
    out << range << " " << bars << std::string(static_cast<std::size_t>(41 - bar), ' ') << count(st.counts[k]) << " ("
        << share(st.counts[k], st.voxels) << ")\n";
  }
  if (!in.from_scene) {
    out << "materials   (a volume file: give a scene to see which voxels each material's range takes)\n";
    return out.str();
  }
  out << "materials   first matching range wins, as the renderer classifies voxel centres (raw values):\n";
  const double span = in.normalisation.max - in.normalisation.min;
  constexpr std::size_t kShownRules = 32;  // a transfer-function image has a rule per run of equal rows
  const auto name_of = [&](const MaterialRule& rule) {
    const std::string& name = in.transfer.materials[static_cast<std::size_t>(rule.material)].name;
    return name.empty() ? "material " + std::to_string(rule.material) : name;
  };
  std::size_t widest = 0;
  for (const MaterialRule& rule : in.transfer.rules) widest = std::max(widest, name_of(rule).size());
  for (std::size_t r = 0; r < in.transfer.rules.size() && r < kShownRules; ++r) {
    const MaterialRule& rule = in.transfer.rules[r];
    const std::string name = name_of(rule);
    const double t0 = (rule.value_lo - in.normalisation.min) / span, t1 = (rule.value_hi - in.normalisation.min) / span;
    out << "  " << name << std::string(widest - name.size(), ' ') << "  [" << num(rule.value_lo) << ", "
        << num(rule.value_hi) << "] (normalised [" << num(t0) << ", " << num(t1) << "]): " << count(st.rule_voxels[r])
        << " voxels (" << share(st.rule_voxels[r], st.voxels) << ")\n";
  }
  if (in.transfer.rules.size() > kShownRules) {
    std::uint64_t rest = 0;
    for (std::size_t r = kShownRules; r < st.rule_voxels.size(); ++r) rest += st.rule_voxels[r];
    out << "  … " << in.transfer.rules.size() - kShownRules << " more ranges: " << count(rest) << " voxels ("
        << share(rest, st.voxels) << ")\n";
  }
  out << "  no material: " << count(st.unassigned) << " voxels (" << share(st.unassigned, st.voxels) << "): empty space\n";
  return out.str();
}

}  // namespace prizma::render
