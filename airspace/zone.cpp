#include "airspace/zone.hpp"

namespace skylane::airspace {

std::string_view restrictionName(Restriction r) {
  switch (r) {
    case Restriction::kProhibited: return "PROHIBITED";
    case Restriction::kReqAuthorisation: return "REQ_AUTHORISATION";
    case Restriction::kConditional: return "CONDITIONAL";
    case Restriction::kNoRestriction: return "NO_RESTRICTION";
  }
  return "?";
}

std::optional<Restriction> parseRestriction(std::string_view text) {
  if (text == "PROHIBITED") return Restriction::kProhibited;
  if (text == "REQ_AUTHORISATION" || text == "REQ_AUTHORIZATION") return Restriction::kReqAuthorisation;
  if (text == "CONDITIONAL") return Restriction::kConditional;
  if (text == "NO_RESTRICTION") return Restriction::kNoRestriction;
  return std::nullopt;
}

std::string_view restrictionLabel(const Zone& z) { return z.keep_in ? "KEEP_IN" : restrictionName(z.restriction); }

std::string_view referenceName(VerticalReference r) {
  switch (r) {
    case VerticalReference::kAgl: return "AGL";
    case VerticalReference::kAmsl: return "AMSL";
    case VerticalReference::kWgs84: return "WGS84";
  }
  return "?";
}

std::string describe(const Zone& z) {
  std::string s = z.source + ": " + z.feature;
  const std::string tag = "(" + z.identifier + ")";
  const bool tagged = z.feature.size() >= tag.size() && z.feature.compare(z.feature.size() - tag.size(), tag.size(), tag) == 0;
  if (!z.identifier.empty() && !tagged) s += " " + tag;
  return s;
}

}  // namespace skylane::airspace
