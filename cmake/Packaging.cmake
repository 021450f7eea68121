# Installation and the Debian package (scripts/package runs CPack with these rules).
#
# What gets installed is the staged workbench (build/workbench/TopOpt: Init.py, InitGui.py,
# package.xml, LICENSE, Resources/, the package topopt/ with the compiled module and the worker
# program topopt/bin/topopt) as FreeCAD's system-wide module folder TopOpt, plus a link
# bin/topopt to the command-line tool. FreeCAD (Debian's 0.20 and later) loads every folder of
# <prefix>/share/freecad/Mod; a user's own Mod/TopOpt (a clone, scripts/install-workbench)
# takes precedence over it, as FreeCAD gives user modules precedence by folder name.

set(TOPOPT_FREECAD_MOD_DIR "share/freecad/Mod/TopOpt" CACHE STRING
    "Where FreeCAD's system-wide module folder TopOpt is installed, relative to the prefix")

install(DIRECTORY ${TOPOPT_WB_DIR}/ DESTINATION ${TOPOPT_FREECAD_MOD_DIR} USE_SOURCE_PERMISSIONS
        PATTERN "__pycache__" EXCLUDE PATTERN "*.pyc" EXCLUDE)

# bin/topopt: a relative link to the worker program (the same binary is the command-line tool)
set(_topopt_link ${CMAKE_BINARY_DIR}/package/topopt)
file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/package)
file(RELATIVE_PATH _topopt_target /usr/bin /usr/${TOPOPT_FREECAD_MOD_DIR}/topopt/bin/topopt)
file(CREATE_LINK ${_topopt_target} ${_topopt_link} SYMBOLIC)
install(FILES ${_topopt_link} DESTINATION bin)

set(CPACK_GENERATOR "DEB")
set(CPACK_PACKAGE_NAME "freecad-topopt")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "TopOpt developers")
set(CPACK_PACKAGE_CONTACT "TopOpt developers <topopt@example.org>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Topology optimisation workbench for FreeCAD")
string(CONCAT CPACK_PACKAGE_DESCRIPTION
       "TopOpt meshes a part and the solids to keep into one conformal tagged tetrahedral mesh "
       "(advancing front, two B-Reps), runs SIMP topology optimisation on it and returns the "
       "optimised shape in FreeCAD, with FEM results of the last iterate.")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_PACKAGING_INSTALL_PREFIX "/usr")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION "science")
set(CPACK_DEBIAN_PACKAGE_PRIORITY "optional")
# the shared libraries the module and the worker link (OCCT, SuiteSparse, Gmsh, TBB, ...) are
# found by dpkg-shlibdeps; FreeCAD, numpy and the Python the module was built for are declared
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(_py "${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}")
math(EXPR _py_next "${Python3_VERSION_MINOR} + 1")
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "freecad (>= 0.20), freecad-python3 (>= 0.20), python3 (>= ${_py}), python3 (<< ${Python3_VERSION_MAJOR}.${_py_next}), python3-numpy")
set(CPACK_PACKAGE_DIRECTORY ${CMAKE_BINARY_DIR}/package)
include(CPack)
