#pragma once
// LightRecord: what a file records about one of its lights (the prizma:lights attribute,
// docs/spectral-exr.md). This header is the only reader and writer of that attribute's JSON, and
// default_spectrum() the only place that decides which spectrum a layer gets when the user names none.
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace prizma::spectral {

struct SpotRecord {
  std::array<double, 3> direction{};  // the cone's axis
  double cone_deg = 0.0;              // half-angle of the cone
  double falloff_deg = 0.0;           // half-angle where the smooth falloff starts
  bool operator==(const SpotRecord&) const = default;
};

struct LightRecord {
  std::string name;      // the light's layer name
  std::string spectrum;  // default spectrum spec ("D65*0.2"); empty when none is recorded
  std::optional<std::array<double, 3>> direction;  // towards a directional light (scene frame)
  std::optional<double> angular_size_deg;           // a directional light's apparent diameter
  bool emission = false;                            // the emission layer (materials' own light)
  std::optional<std::array<double, 3>> position;    // point, sphere and spot lights
  double radius = 0.0;                              // sphere lights: > 0
  std::optional<SpotRecord> spot;                   // spot lights
  std::optional<std::string> environment;           // environment map, the file as the scene names it
  double rotation_deg = 0.0;                        // the environment map's rotation about +y
  bool operator==(const LightRecord&) const = default;
};

// A record of a name and a spectrum spec, nothing else set (a relit image's lights, tests).
LightRecord light_record(std::string name, std::string spectrum = {});

// Parses prizma:lights: a JSON array of objects with the fields above (unknown fields are ignored,
// absent ones stay unset). Throws InputError(input, …) for text that is not JSON, nested deeper than
// 128 levels, not an array of objects, or with a field of the wrong type, naming the entry.
std::vector<LightRecord> parse_light_records(std::string_view text, const std::string& input);

// The JSON text of prizma:lights: one object per record with the fields that are set, keys in
// alphabetical order ("name" always; "spectrum" when not empty).
std::string light_records_json(const std::vector<LightRecord>& records);

// Records that name the layers and nothing else (what a file gets when its writer records no lights).
std::vector<LightRecord> light_records_for(const std::vector<std::string>& layer_names);

// Refuses records that do not describe these layers: two records of one name, or, when two or more
// lights are recorded, a record without a layer of its name. Throws InputError(input, …).
void check_light_records(const std::vector<LightRecord>& records, const std::vector<std::string>& layer_names,
                         const std::string& input);

// The spectrum spec a layer gets when the user names none: the spectrum recorded for the layer's name;
// in a file with one layer and one record, that record's whatever its name (a single-light render's
// layer is the top level); "D65" when nothing is recorded.
std::string default_spectrum(const std::vector<LightRecord>& records, std::string_view layer,
                             std::size_t layer_count);

}  // namespace prizma::spectral
