# gilab_add_technique(<id> [DIR <folder>] [SOURCES <files...>] [SHADERS <files...>])
#
# A technique is one folder (docs/architecture.md, "One folder per technique"):
#   <folder>/*.cpp, *.h          its code; the .cpp ends with GILAB_REGISTER_TECHNIQUE(...)
#   <folder>/shaders/            its GLSL stages (.vert .geom .frag .comp) and .glsl includes,
#                                registered as "<id>/<file>"
#   <folder>/known_weaknesses.json  the audit cases it is expected to fail, and why (optional;
#                                docs/audit.md, "Declared weaknesses"), embedded as
#                                "<id>/known_weaknesses.json"
#   <folder>/README.md, paper.json, configs/, tests/   its page, paper facts, configs and tests
# In the tree (GILAB_IN_TREE) the folder defaults to techniques/<id>/ and the technique is an
# OBJECT library linked into gilab and the tests (a static library would let the linker drop its
# self-registration). Out of the tree (find_package(gilab)) the folder defaults to the calling
# CMakeLists.txt's and the technique is a loadable module, gilab-technique-<id>.so, that gilab
# loads at start (docs/tutorial.md, "Your technique in your own repository").
# Without SOURCES every <folder>/*.cpp and every stage in <folder>/shaders/ is taken. With
# SOURCES, SHADERS must list every stage in <folder>/shaders/: an unlisted one is an error here,
# not a missing shader at run time.
include(${CMAKE_CURRENT_LIST_DIR}/GilabShaders.cmake)

set(GILAB_CMAKE_DIR ${CMAKE_CURRENT_LIST_DIR} CACHE INTERNAL "gilab's CMake helpers")

# Registers the text of <file> under <name> in <target> (core/util/embedded_text.h).
function(gilab_embed_text target name file)
    string(MAKE_C_IDENTIFIER "${name}" stem)
    set(cpp ${CMAKE_CURRENT_BINARY_DIR}/embedded/${stem}.cpp)
    add_custom_command(
        OUTPUT ${cpp}
        COMMAND ${CMAKE_COMMAND} -DIN=${file} -DOUT=${cpp} -DNAME=${name}
                -P ${GILAB_CMAKE_DIR}/GilabEmbedText.cmake
        DEPENDS ${file} ${GILAB_CMAKE_DIR}/GilabEmbedText.cmake
        COMMENT "Embedding ${name}"
        VERBATIM)
    target_sources(${target} PRIVATE ${cpp})
endfunction()

function(gilab_add_technique id)
    cmake_parse_arguments(ARG "" "DIR" "SOURCES;SHADERS" ${ARGN})
    if(NOT id MATCHES "^[a-z][a-z0-9_]*$")
        message(FATAL_ERROR "gilab_add_technique(${id}): an id is lower case letters, digits and _")
    endif()
    if(NOT ARG_DIR)
        if(GILAB_IN_TREE)
            set(ARG_DIR ${CMAKE_SOURCE_DIR}/techniques/${id})
        else()
            set(ARG_DIR ${CMAKE_CURRENT_SOURCE_DIR})
        endif()
    endif()
    get_filename_component(ARG_DIR ${ARG_DIR} ABSOLUTE BASE_DIR ${CMAKE_CURRENT_SOURCE_DIR})
    file(GLOB stages CONFIGURE_DEPENDS ${ARG_DIR}/shaders/*.vert ${ARG_DIR}/shaders/*.geom
         ${ARG_DIR}/shaders/*.frag ${ARG_DIR}/shaders/*.comp)
    if(NOT ARG_SOURCES)
        file(GLOB ARG_SOURCES CONFIGURE_DEPENDS ${ARG_DIR}/*.cpp)
        set(ARG_SHADERS ${stages})
        if(NOT ARG_SOURCES)
            message(STATUS "technique ${id}: no sources in ${ARG_DIR}/, left out")
            return()
        endif()
    else()
        list(TRANSFORM ARG_SOURCES PREPEND ${ARG_DIR}/ REGEX "^[^/]")
        list(TRANSFORM ARG_SHADERS PREPEND ${ARG_DIR}/ REGEX "^[^/]")
        foreach(stage ${stages})
            if(NOT stage IN_LIST ARG_SHADERS)
                file(RELATIVE_PATH shown ${ARG_DIR} ${stage})
                message(FATAL_ERROR "gilab_add_technique(${id}): ${stage} is not in SHADERS; list "
                        "every stage of ${ARG_DIR}/shaders/ (SHADERS shaders/a.comp ...), or give "
                        "neither SOURCES nor SHADERS to take the whole folder")
            endif()
        endforeach()
    endif()
    set(target gilab_technique_${id})
    if(GILAB_IN_TREE)
        add_library(${target} OBJECT ${ARG_SOURCES})
        target_link_libraries(${target} PUBLIC gilab_core)
        target_compile_options(${target} PRIVATE ${GILAB_WARNINGS})
        set_property(GLOBAL APPEND PROPERTY GILAB_TECHNIQUE_TARGETS ${target})
    else()
        add_library(${target} MODULE ${ARG_SOURCES} ${GILAB_CMAKE_DIR}/gilab_module_abi.cpp)
        target_link_libraries(${target} PRIVATE gilab::core)
        target_compile_features(${target} PRIVATE cxx_std_20)
        set_target_properties(${target} PROPERTIES PREFIX "" OUTPUT_NAME gilab-technique-${id})
        # `cmake --install` into gilab's prefix puts it where gilab looks beside itself.
        install(TARGETS ${target} LIBRARY DESTINATION ${GILAB_MODULE_INSTALL_DIR})
    endif()
    if(ARG_SHADERS)
        gilab_add_shaders(${target} BASE ${ARG_DIR}/shaders PREFIX ${id}/ SOURCES ${ARG_SHADERS})
    endif()
    # Globbed so that adding the file later reconfigures.
    file(GLOB weaknesses CONFIGURE_DEPENDS ${ARG_DIR}/known_weaknesses.json)
    if(weaknesses)
        gilab_embed_text(${target} ${id}/known_weaknesses.json ${ARG_DIR}/known_weaknesses.json)
    endif()
    set_property(GLOBAL APPEND PROPERTY GILAB_TECHNIQUE_DIRS ${ARG_DIR})
endfunction()

# Links every self-registering OBJECT library (the in-tree techniques) into <target>.
function(gilab_link_plugins target)
    get_property(techniques GLOBAL PROPERTY GILAB_TECHNIQUE_TARGETS)
    foreach(t ${techniques})
        target_sources(${target} PRIVATE $<TARGET_OBJECTS:${t}>)
        target_link_libraries(${target} PRIVATE ${t})
    endforeach()
endfunction()
