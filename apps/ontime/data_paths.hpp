#pragma once
// Where the project's data files are found at run time (world files and instances of the
// domains), and where `collect` writes by default.
//
// `collect` writes into the current directory (data/logs/NAME.jsonl, data/instances/NAME.json),
// never into the installed data; `run` reads its model from the current directory's
// data/instances/NAME.json when there is one (what `collect` wrote there), else the instance
// shipped in the data directory. In the source tree's root both are the same file.

#include <filesystem>
#include <string>

namespace ontime::cli {

// $ONTIME_DATA_DIR, else share/ontime/data installed beside this executable (../share/ontime/data
// from its bin/), else the source tree's data/ (running from a build tree).
std::filesystem::path data_directory();

// The world file of a domain: data_directory()/domains/NAME.json.
std::filesystem::path default_world_file(const std::string& domain);

// What `collect` writes by default, relative to the current directory:
// data/logs/NAME.jsonl and data/instances/NAME.json.
std::filesystem::path collected_log_file(const std::string& domain);
std::filesystem::path collected_instance_file(const std::string& domain);

// The model `run` uses by default: collected_instance_file(domain) when it exists, else
// data_directory()/instances/NAME.json.
std::filesystem::path default_model_file(const std::string& domain);

}  // namespace ontime::cli
