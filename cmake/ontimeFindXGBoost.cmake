# XGBoost's C API (Debian's libxgboost-dev), as the imported target ontime::xgboost: for the
# build (CMakeLists.txt) and for consumers of the installed package (ontimeConfig.cmake), since
# the static core library links it. Found by its header and library rather than by XGBoost's own
# CMake package: the one libxgboost-dev ships also imports the `xgboost` executable, which that
# package does not install, so find_package(xgboost) stops with an error on Debian.
# Sets XGBoost_FOUND; defines the target only when both are found.
find_path(XGBoost_INCLUDE_DIR xgboost/c_api.h)
find_library(XGBoost_LIBRARY xgboost)
mark_as_advanced(XGBoost_INCLUDE_DIR XGBoost_LIBRARY)
if(XGBoost_INCLUDE_DIR AND XGBoost_LIBRARY)
  set(XGBoost_FOUND TRUE)
  if(NOT TARGET ontime::xgboost)
    add_library(ontime::xgboost UNKNOWN IMPORTED)
    set_target_properties(ontime::xgboost PROPERTIES
      IMPORTED_LOCATION "${XGBoost_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${XGBoost_INCLUDE_DIR}")
  endif()
else()
  set(XGBoost_FOUND FALSE)
endif()
