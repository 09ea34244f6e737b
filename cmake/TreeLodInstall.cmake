# `cmake --install build --prefix P`: what goes where (docs/ogre-integration.md, "Installing").
#
#   P/lib/OGRE/Plugin_TreeLod.so           the plugin, and Plugin_TreeLod.so.<OGRE version> linking
#                                          to it: the name OGRE opens for `Plugin=Plugin_TreeLod`
#   P/share/TreeLod/media                  material scripts, programs, TreeLodWhite.png, GLSL/
#   P/share/TreeLod/plot.py                the bench's plots (treelod bench)
#   P/bin/treelod, P/bin/treelod_frames    the tools (RUNPATH $ORIGIN/../lib/OGRE; data from ../share/TreeLod)
#   P/include/TreeLod/*.h                  public headers of the exported libraries
#   P/lib/libTreeLod*.a                    the static libraries behind the exported targets
#   P/lib/cmake/TreeLod                    the CMake package: find_package(TreeLod CONFIG)
#
# Exported targets (namespace TreeLod::), named for what a user wants rather than how the build
# splits them (cmake/TreeLodTechnique.cmake):
#   TreeLod::TreeLodRuntime  = TreeLodTechniques: the package reader and LoD math with every
#                              technique's runtime half (chunk formats, descriptors) linked whole
#   TreeLod::TreeLodBake     = TreeLodBakeTechniques: import, bake, metrics, with every technique's
#                              baker linked whole (and TreeLod::TreeLodRuntime)
#   TreeLod::Plugin_TreeLod  the Ogre plugin (links TreeLod::TreeLodRuntime's interface, OgreMain)
#   TreeLod::TreeLodRuntimeCore, TreeLod::TreeLodBakeCore, TreeLod::TreeLodScript and
#   TreeLod::TreeLod<technique>Runtime/Bake: the parts the three above are made of.

# ---- targets --------------------------------------------------------------------------
set_target_properties(TreeLodTechniques PROPERTIES EXPORT_NAME TreeLodRuntime)
set_target_properties(TreeLodRuntime PROPERTIES EXPORT_NAME TreeLodRuntimeCore)
set_target_properties(TreeLodBakeTechniques PROPERTIES EXPORT_NAME TreeLodBake)
set_target_properties(TreeLodBake PROPERTIES EXPORT_NAME TreeLodBakeCore)
get_property(treelod_technique_targets GLOBAL PROPERTY TREELOD_TECHNIQUE_TARGETS)
install(TARGETS TreeLodRuntime TreeLodScript TreeLodBake TreeLodTechniques TreeLodBakeTechniques
                ${treelod_technique_targets}
  EXPORT TreeLodTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})

if(TARGET Plugin_TreeLod)
  install(TARGETS Plugin_TreeLod EXPORT TreeLodTargets
    LIBRARY DESTINATION ${TREELOD_INSTALL_PLUGINDIR})
  # Debian's OGRE appends ".so.<its version>" to every name in plugins.cfg (OGRE-NOTES.md).
  set(treelod_plugin_alias Plugin_TreeLod.so.${OGRE_VERSION})
  install(CODE "
    file(CREATE_LINK Plugin_TreeLod.so
      \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${TREELOD_INSTALL_PLUGINDIR}/${treelod_plugin_alias}\" SYMBOLIC)
    message(STATUS \"Installing: \$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${TREELOD_INSTALL_PLUGINDIR}/${treelod_plugin_alias}\")")
endif()

# ---- tools -----------------------------------------------------------------------------
foreach(tool treelod treelod_frames)
  if(TARGET ${tool})
    file(RELATIVE_PATH plugin_from_bin ${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}
                                       ${CMAKE_INSTALL_PREFIX}/${TREELOD_INSTALL_PLUGINDIR})
    set_target_properties(${tool} PROPERTIES INSTALL_RPATH "$ORIGIN/${plugin_from_bin}")
    install(TARGETS ${tool} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
endforeach()

# ---- data: the plot script; the media (materials/ and every technique's media/, merged into one
# folder) are installed by treelod_merge_media (cmake/TreeLodTechnique.cmake) ----
install(FILES ${PROJECT_SOURCE_DIR}/bench/plot.py DESTINATION ${TREELOD_INSTALL_DATADIR})

# ---- headers: those of the exported libraries (OffscreenRenderer.h and OgreBootstrap.h belong to
# TreeLodOffscreen, which the tools link and the package does not export) ----
set(treelod_header_dirs
  ${PROJECT_SOURCE_DIR}/plugin/core/runtime/include
  ${PROJECT_SOURCE_DIR}/plugin/core/script/include
  ${PROJECT_SOURCE_DIR}/plugin/core/bake/include)
foreach(target IN LISTS treelod_technique_targets)
  get_target_property(dir ${target} SOURCE_DIR)
  list(APPEND treelod_header_dirs ${dir}/include)
endforeach()
if(TARGET Plugin_TreeLod)
  list(APPEND treelod_header_dirs ${PROJECT_SOURCE_DIR}/plugin/ogre/include)
endif()
list(REMOVE_DUPLICATES treelod_header_dirs)
foreach(dir IN LISTS treelod_header_dirs)
  install(DIRECTORY ${dir}/TreeLod DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
    FILES_MATCHING PATTERN "*.h" PATTERN "OffscreenRenderer.h" EXCLUDE PATTERN "OgreBootstrap.h" EXCLUDE)
endforeach()

# ---- the CMake package ---------------------------------------------------------------------
include(CMakePackageConfigHelpers)
install(EXPORT TreeLodTargets NAMESPACE TreeLod:: DESTINATION ${TREELOD_INSTALL_CMAKEDIR})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/TreeLodConfig.cmake.in
  ${CMAKE_BINARY_DIR}/TreeLodConfig.cmake
  INSTALL_DESTINATION ${TREELOD_INSTALL_CMAKEDIR}
  PATH_VARS TREELOD_INSTALL_PLUGINDIR TREELOD_INSTALL_DATADIR)
write_basic_package_version_file(${CMAKE_BINARY_DIR}/TreeLodConfigVersion.cmake
  COMPATIBILITY SameMinorVersion) # 0.x: a minor version may change the package format
install(FILES ${CMAKE_BINARY_DIR}/TreeLodConfig.cmake ${CMAKE_BINARY_DIR}/TreeLodConfigVersion.cmake
  DESTINATION ${TREELOD_INSTALL_CMAKEDIR})
