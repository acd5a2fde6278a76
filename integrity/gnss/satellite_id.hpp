#pragma once
/// \file
/// \brief Constellations and satellite identifiers ("G01", "E11").

#include <array>
#include <functional>
#include <optional>
#include <string>

namespace skylane::integrity {

/// \brief GNSS constellations skylane knows. The order is the index used in arrays.
enum class Constellation { kGps = 0, kGalileo = 1, kGlonass = 2, kBeidou = 3 };
inline constexpr int kNumConstellations = 4;
inline constexpr std::array<Constellation, kNumConstellations> kAllConstellations = {
    Constellation::kGps, Constellation::kGalileo, Constellation::kGlonass, Constellation::kBeidou};

/// \brief RINEX system letter: G, E, R, C.
[[nodiscard]] char constellationLetter(Constellation c);
/// \brief Name used in JSON and reports: "GPS", "Galileo", "GLONASS", "BeiDou".
[[nodiscard]] const char* constellationName(Constellation c);
/// \brief Constellation from its RINEX letter; nullopt for other letters.
[[nodiscard]] std::optional<Constellation> constellationFromLetter(char letter);
/// \brief Constellation from its name (case-insensitive "GPS", "Galileo", …); nullopt otherwise.
[[nodiscard]] std::optional<Constellation> constellationFromName(const std::string& name);

/// \brief One satellite: constellation and PRN (slot) number.
struct SatId {
  Constellation constellation = Constellation::kGps;
  int prn = 0;

  /// \brief "G01", "E24".
  [[nodiscard]] std::string str() const;
  friend bool operator==(const SatId& a, const SatId& b) {
    return a.constellation == b.constellation && a.prn == b.prn;
  }
  friend bool operator!=(const SatId& a, const SatId& b) { return !(a == b); }
  friend bool operator<(const SatId& a, const SatId& b) {
    return a.constellation != b.constellation ? a.constellation < b.constellation : a.prn < b.prn;
  }
};

/// \brief Parses "G01", "G 1", "E11"; a bare number ("12") is GPS as in RINEX 2.
/// \returns nullopt when the text is not a satellite id.
[[nodiscard]] std::optional<SatId> parseSatId(const std::string& text);

}  // namespace skylane::integrity
