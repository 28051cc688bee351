#pragma once
// The live page's view state: what its URL fragment holds, e.g.
//   light.side=A&light.back=off&exposure=1&cmf=1931&display=sRGB&adapt=0
// as key/value pairs (already URL-decoded), turned into RelightSettings by the same parsers the
// command line uses, and back (docs/relight.md, "Live page").
#include <string>
#include <utility>
#include <vector>

#include "prizma/relight/relight_session.h"

namespace prizma::relight {

using StateParams = std::vector<std::pair<std::string, std::string>>;

// `base` with the keys of `params` applied: light.NAME (a light spec, "off", trailing "*scale"),
// exposure (EV, within ±64), cmf (1931, 1964, 2012-2, 2012-10), display (a display of the OCIO
// config), adapt (0/1). Keys missing keep `base`. A spec naming a file (csv:) is refused unless it is
// the light's default, so no request reaches the file system. Throws InputError naming the key.
RelightSettings settings_from_state(const StateParams& params, const RelightSession& session,
                                    const RelightSettings& base);

// The canonical state string of `settings` (every key, URL-encoded values).
std::string state_string(const RelightSettings& settings, const RelightSession& session);

// "1931", "1964", "2012-2", "2012-10": the state's names for the observers.
std::string observer_state_name(spectral::Observer observer);

// Percent-encoding of everything but A–Z a–z 0–9 - _ . ~ * : (as the page's JavaScript writes it).
std::string url_encode(const std::string& text);

}  // namespace prizma::relight
