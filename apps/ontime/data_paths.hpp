#pragma once
// Where the project's data files are found at run time (world files of the domains).

#include <filesystem>
#include <string>

namespace ontime::cli {

// $ONTIME_DATA_DIR, else the source tree's data/ when running from a build tree, else the
// installed share/ontime/data.
std::filesystem::path data_directory();

// The world file of a domain: data_directory()/domains/NAME.json.
std::filesystem::path default_world_file(const std::string& domain);

}  // namespace ontime::cli
