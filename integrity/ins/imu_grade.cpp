#include "integrity/ins/imu_grade.hpp"

namespace skylane::integrity::ins {

std::string_view imuGradeName(ImuGrade g) {
  switch (g) {
    case ImuGrade::kAviation: return "aviation";
    case ImuGrade::kTactical: return "tactical";
    case ImuGrade::kConsumer: return "consumer";
  }
  return "?";
}

std::optional<ImuGrade> parseImuGrade(std::string_view name) {
  for (ImuGrade g : {ImuGrade::kAviation, ImuGrade::kTactical, ImuGrade::kConsumer}) {
    if (imuGradeName(g) == name) return g;
  }
  return std::nullopt;
}

ImuSpec imuSpec(ImuGrade g) {
  ImuSpec s;
  switch (g) {
    case ImuGrade::kAviation:
      s = {3e-4, 5e-8, 2e-4, 5.8e-7, 1e-6, 1e-9, 100.0};
      break;
    case ImuGrade::kTactical:
      s = {1e-2, 5e-6, 8.3e-4, 2.9e-5, 1e-4, 1e-7, 100.0};
      break;
    case ImuGrade::kConsumer:
      s = {3e-2, 5e-4, 2.0e-3, 1.75e-4, 3e-4, 1e-5, 100.0};
      break;
  }
  return s;
}

}  // namespace skylane::integrity::ins
