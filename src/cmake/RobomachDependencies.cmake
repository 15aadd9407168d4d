# Finds robomach's dependencies and makes imported targets for the ones that
# ship none (style.md §4). Used both in-tree (every dependency) and by
# robomachConfig.cmake, which sets ROBOMACH_NEEDED_DEPS to the dependencies
# of the components a consumer asked for, so that
# find_package(robomach COMPONENTS dynamics) looks for Eigen and KDL only.
include(CMakeFindDependencyMacro)
if(NOT DEFINED ROBOMACH_NEEDED_DEPS)
  set(ROBOMACH_NEEDED_DEPS Eigen3 kdl urdfdom yaml-cpp Ceres NLopt opencv clipper json Threads occt)
endif()
macro(robomach_needs dep out)
  list(FIND ROBOMACH_NEEDED_DEPS ${dep} _robomach_idx)
  if(_robomach_idx EQUAL -1)
    set(${out} FALSE)
  else()
    set(${out} TRUE)
  endif()
endmacro()
robomach_needs(Eigen3 _need)
if(_need)
  find_dependency(Eigen3 3.3 NO_MODULE)
endif()
robomach_needs(kdl _need)
if(_need)
  find_dependency(orocos_kdl)
  if(NOT TARGET robomach_dep::kdl)
    add_library(robomach_dep::kdl INTERFACE IMPORTED)
    find_library(ROBOMACH_KDL_LIBRARY NAMES orocos-kdl REQUIRED)
    set_target_properties(robomach_dep::kdl PROPERTIES
      INTERFACE_LINK_LIBRARIES "${ROBOMACH_KDL_LIBRARY};Eigen3::Eigen"
      INTERFACE_INCLUDE_DIRECTORIES "${orocos_kdl_INCLUDE_DIRS}")
  endif()
endif()
robomach_needs(urdfdom _need)
if(_need)
  find_dependency(urdfdom)
  find_dependency(console_bridge)
  if(NOT TARGET robomach_dep::urdfdom)
    add_library(robomach_dep::urdfdom INTERFACE IMPORTED)
    set_target_properties(robomach_dep::urdfdom PROPERTIES
      INTERFACE_LINK_LIBRARIES "${urdfdom_LIBRARIES};${console_bridge_LIBRARIES}"
      INTERFACE_INCLUDE_DIRECTORIES "${urdfdom_INCLUDE_DIRS}")
  endif()
endif()
robomach_needs(yaml-cpp _need)
if(_need)
  find_dependency(yaml-cpp)
endif()
robomach_needs(Ceres _need)
if(_need)
  find_dependency(Ceres)
endif()
robomach_needs(NLopt _need)
if(_need)
  find_dependency(NLopt)
  if(NOT TARGET robomach_dep::nlopt)
    add_library(robomach_dep::nlopt INTERFACE IMPORTED)
    set_target_properties(robomach_dep::nlopt PROPERTIES
      INTERFACE_LINK_LIBRARIES "${NLOPT_LIBRARIES}"
      INTERFACE_INCLUDE_DIRECTORIES "${NLOPT_INCLUDE_DIRS}")
  endif()
endif()
robomach_needs(opencv _need)
if(_need)
  # The minimal Debian OpenCV packages ship no CMake config.
  if(NOT TARGET robomach_dep::opencv)
    find_path(ROBOMACH_OPENCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4 REQUIRED)
    find_library(ROBOMACH_OPENCV_CORE opencv_core REQUIRED)
    find_library(ROBOMACH_OPENCV_IMGPROC opencv_imgproc REQUIRED)
    find_library(ROBOMACH_OPENCV_IMGCODECS opencv_imgcodecs REQUIRED)
    add_library(robomach_dep::opencv INTERFACE IMPORTED)
    set_target_properties(robomach_dep::opencv PROPERTIES
      INTERFACE_LINK_LIBRARIES "${ROBOMACH_OPENCV_IMGCODECS};${ROBOMACH_OPENCV_IMGPROC};${ROBOMACH_OPENCV_CORE}"
      INTERFACE_INCLUDE_DIRECTORIES "${ROBOMACH_OPENCV_INCLUDE_DIR}")
  endif()
endif()
robomach_needs(clipper _need)
if(_need)
  # Clipper 6 (Debian's libpolyclipping-dev ships no CMake config): polygon
  # offsets of trimmed polishing regions (polishing/region_outline).
  if(NOT TARGET robomach_dep::clipper)
    find_path(ROBOMACH_CLIPPER_INCLUDE_DIR polyclipping/clipper.hpp REQUIRED)
    find_library(ROBOMACH_CLIPPER_LIBRARY polyclipping REQUIRED)
    add_library(robomach_dep::clipper INTERFACE IMPORTED)
    set_target_properties(robomach_dep::clipper PROPERTIES
      INTERFACE_LINK_LIBRARIES "${ROBOMACH_CLIPPER_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${ROBOMACH_CLIPPER_INCLUDE_DIR}")
  endif()
endif()
robomach_needs(json _need)
if(_need)
  find_dependency(nlohmann_json)
endif()
robomach_needs(Threads _need)
if(_need)
  find_package(Threads REQUIRED)
endif()
robomach_needs(occt _need)
if(_need)
  # OpenCASCADE (Debian's libocct-*-dev 7.6) reads STEP and IGES faces for the
  # polishing tools (io/cad_face). Only the toolkits the reader needs.
  find_dependency(OpenCASCADE)
  if(NOT TARGET robomach_dep::occt)
    add_library(robomach_dep::occt INTERFACE IMPORTED)
    set_target_properties(robomach_dep::occt PROPERTIES
      INTERFACE_LINK_LIBRARIES "TKSTEP;TKIGES;TKXSBase;TKShHealing;TKTopAlgo;TKGeomAlgo;TKBRep;TKGeomBase;TKG3d;TKG2d;TKMath;TKernel"
      INTERFACE_INCLUDE_DIRECTORIES "${OpenCASCADE_INCLUDE_DIR}")
  endif()
endif()
