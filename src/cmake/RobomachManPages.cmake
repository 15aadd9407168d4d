# Man pages of the tools (section 1), generated from each tool's --help by
# help2man (Debian package help2man) and installed to share/man/man1.
# Optional: without help2man nothing is built or installed, and the build
# does not need it; -DROBOMACH_HELP2MAN=OFF turns the pages off.
# Included at the end of apps/CMakeLists.txt: every executable defined there
# gets a page. NAME is the first sentence of its --help; SEE ALSO names its
# manual in docs/, taken from the README's tool table (the docs.links test
# checks that every tool has a row there with a link to its page).
find_program(ROBOMACH_HELP2MAN help2man)
if(ROBOMACH_HELP2MAN)
  file(STRINGS ${PROJECT_SOURCE_DIR}/README.md robomach_tool_rows REGEX "^\\| `[a-z0-9-]+` \\|")
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/README.md)
  get_property(robomach_app_targets DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR} PROPERTY BUILDSYSTEM_TARGETS)
  set(robomach_man_pages "")
  foreach(tool ${robomach_app_targets})
    get_target_property(type ${tool} TYPE)
    if(NOT type STREQUAL "EXECUTABLE")
      continue()
    endif()
    set(doc "")
    foreach(row ${robomach_tool_rows})
      if(row MATCHES "^\\| `${tool}` \\|.*\\]\\(docs/([a-z0-9-]+\\.md)")
        set(doc ${CMAKE_MATCH_1})
      endif()
    endforeach()
    set(page ${CMAKE_CURRENT_BINARY_DIR}/man/${tool}.1)
    add_custom_command(OUTPUT ${page}
      COMMAND ${CMAKE_COMMAND} -DHELP2MAN=${ROBOMACH_HELP2MAN} -DTOOL=$<TARGET_FILE:${tool}>
              -DNAME=${tool} -DVERSION=${PROJECT_VERSION} -DDOC=${doc}
              -DDOCDIR=${CMAKE_INSTALL_FULL_DOCDIR} -DOUT=${page}
              -P ${PROJECT_SOURCE_DIR}/src/cmake/RobomachManPage.cmake
      DEPENDS ${tool} ${PROJECT_SOURCE_DIR}/src/cmake/RobomachManPage.cmake
      COMMENT "man page ${tool}.1 (help2man)" VERBATIM)
    list(APPEND robomach_man_pages ${page})
  endforeach()
  add_custom_target(man-pages ALL DEPENDS ${robomach_man_pages})
  # OPTIONAL: an install from a tree where only some tools were built skips
  # the pages that were not made instead of failing.
  install(FILES ${robomach_man_pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 OPTIONAL)
endif()
