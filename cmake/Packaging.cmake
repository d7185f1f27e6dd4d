# The Debian package `ontime` (CPack's DEB generator: `cpack -G DEB` in a configured and built
# tree; scripts/check-package.sh builds, installs and removes it). It holds what `cmake --install`
# installs, under /usr: the ontime tool, the libraries with their headers and CMake package
# (find_package(ontime)), the data and plotting scripts under share/ontime, and the Python package
# in /usr/lib/python3/dist-packages. Nothing compiled in names the build's prefix: the tool finds
# its data relative to itself, and the Python folder is chosen for the prefix when installing.
set(CPACK_PACKAGE_NAME ontime)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
set(CPACK_PACKAGE_DESCRIPTION
  "OnTime decides, one step of planner effort at a time, which candidate plan skeleton a motion
planner refines next, so that some skeleton is refined and executed before a deadline. The
package holds the ontime tool, the C++ library (headers, static libraries, CMake package) and
the Python package ontime.")
set(ONTIME_PACKAGE_MAINTAINER "OnTime maintainers <maintainers@ontime.invalid>" CACHE STRING
  "Maintainer field of the Debian package")
set(CPACK_PACKAGE_CONTACT "${ONTIME_PACKAGE_MAINTAINER}")
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
# The shared libraries the tool and the extension link (Open MPI, OMPL, FCL, Boost, fmt, abseil,
# SLEEF, ...), found by dpkg-shlibdeps.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(depends)
if(ONTIME_PYTHON)
  # The extension is built for one Python version (its ABI tag), as Debian's ${python3:Depends}.
  math(EXPR next_minor "${Python3_VERSION_MINOR} + 1")
  list(APPEND depends
    "python3 (>= ${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}~)"
    "python3 (<< ${Python3_VERSION_MAJOR}.${next_minor})"
    python3-numpy)
endif()
list(JOIN depends ", " CPACK_DEBIAN_PACKAGE_DEPENDS)
# `ontime plot` and the other drawing commands run the plotting scripts with matplotlib; building
# against the library (find_package(ontime)) needs the development packages its CMake package
# looks for (Eigen, OMPL, FCL and KDL only for the domains component).
set(recommends python3-matplotlib libfmt-dev libabsl-dev libsleef-dev libxgboost-dev pkg-config)
if(ONTIME_BUILD_DOMAINS)
  list(APPEND recommends libeigen3-dev libompl-dev libfcl-dev liborocos-kdl-dev)
endif()
list(JOIN recommends ", " CPACK_DEBIAN_PACKAGE_RECOMMENDS)
# Byte-compiling the Python files on installation and removing the compiled files on removal.
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
  ${CMAKE_CURRENT_LIST_DIR}/debian/postinst ${CMAKE_CURRENT_LIST_DIR}/debian/prerm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
