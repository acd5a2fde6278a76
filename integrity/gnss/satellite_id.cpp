#include "integrity/gnss/satellite_id.hpp"

#include <cctype>
#include <cstdio>

namespace skylane::integrity {

char constellationLetter(Constellation c) {
  switch (c) {
    case Constellation::kGps: return 'G';
    case Constellation::kGalileo: return 'E';
    case Constellation::kGlonass: return 'R';
    case Constellation::kBeidou: return 'C';
  }
  return '?';
}

const char* constellationName(Constellation c) {
  switch (c) {
    case Constellation::kGps: return "GPS";
    case Constellation::kGalileo: return "Galileo";
    case Constellation::kGlonass: return "GLONASS";
    case Constellation::kBeidou: return "BeiDou";
  }
  return "?";
}

std::optional<Constellation> constellationFromLetter(char letter) {
  switch (std::toupper(static_cast<unsigned char>(letter))) {
    case 'G': return Constellation::kGps;
    case 'E': return Constellation::kGalileo;
    case 'R': return Constellation::kGlonass;
    case 'C': return Constellation::kBeidou;
    default: return std::nullopt;
  }
}

std::optional<Constellation> constellationFromName(const std::string& name) {
  std::string up;
  for (char ch : name) up += static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  if (up == "GPS") return Constellation::kGps;
  if (up == "GALILEO" || up == "GAL") return Constellation::kGalileo;
  if (up == "GLONASS" || up == "GLO") return Constellation::kGlonass;
  if (up == "BEIDOU" || up == "BDS") return Constellation::kBeidou;
  return std::nullopt;
}

std::string SatId::str() const {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%c%02d", constellationLetter(constellation), prn % 100);
  return buf;
}

std::optional<SatId> parseSatId(const std::string& text) {
  std::size_t i = 0;
  while (i < text.size() && text[i] == ' ') ++i;
  if (i == text.size()) return std::nullopt;
  SatId id;
  if (std::isalpha(static_cast<unsigned char>(text[i]))) {
    const auto c = constellationFromLetter(text[i]);
    if (!c) return std::nullopt;
    id.constellation = *c;
    ++i;
  }
  while (i < text.size() && text[i] == ' ') ++i;
  if (i == text.size()) return std::nullopt;
  int prn = 0;
  std::size_t digits = 0;
  for (; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i, ++digits) {
    prn = prn * 10 + (text[i] - '0');
    if (digits >= 2) return std::nullopt;  // PRNs have at most two digits (RINEX)
  }
  while (i < text.size() && text[i] == ' ') ++i;
  if (digits == 0 || i != text.size() || prn < 1) return std::nullopt;
  id.prn = prn;
  return id;
}

}  // namespace skylane::integrity
