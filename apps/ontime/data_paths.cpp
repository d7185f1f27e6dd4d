#include "data_paths.hpp"

#include <cstdlib>

#include "install_paths.hpp"

namespace ontime::cli {

std::filesystem::path data_directory() {
  if (const char* override_dir = std::getenv("ONTIME_DATA_DIR")) return override_dir;
  std::filesystem::path installed = beside_executable(ONTIME_DATA_FROM_BINDIR);
  std::error_code error;
  if (std::filesystem::is_directory(installed, error)) return installed;
  if (std::filesystem::is_directory(ONTIME_DATA_SOURCE_DIR, error)) return ONTIME_DATA_SOURCE_DIR;
  return installed;
}

std::filesystem::path default_world_file(const std::string& domain) {
  return data_directory() / "domains" / (domain + ".json");
}

std::filesystem::path collected_log_file(const std::string& domain) {
  return std::filesystem::path("data") / "logs" / (domain + ".jsonl");
}

std::filesystem::path collected_instance_file(const std::string& domain) {
  return std::filesystem::path("data") / "instances" / (domain + ".json");
}

std::filesystem::path default_model_file(const std::string& domain) {
  std::filesystem::path collected = collected_instance_file(domain);
  std::error_code error;
  if (std::filesystem::is_regular_file(collected, error)) return collected;
  return data_directory() / "instances" / (domain + ".json");
}

}  // namespace ontime::cli
