# gilab_add_technique(<id> [SOURCES <files...>] [SHADERS <files...>])
#
# A technique is techniques/<id>/ plus shaders/<id>/ and this one line in the top-level table.
# Without SOURCES, every techniques/<id>/*.cpp and every shaders/<id>/ stage (.vert .geom .frag
# .comp) is taken; a technique whose folder has no .cpp yet is left out with a message.
# It builds as an OBJECT library so the GILAB_REGISTER_TECHNIQUE object in its .cpp is always
# linked into gilab and the tests (a static library would let the linker drop it).
function(gilab_add_technique id)
    cmake_parse_arguments(ARG "" "" "SOURCES;SHADERS" ${ARGN})
    if(NOT ARG_SOURCES)
        file(GLOB ARG_SOURCES CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/techniques/${id}/*.cpp)
        file(GLOB ARG_SHADERS CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/shaders/${id}/*.vert
             ${CMAKE_SOURCE_DIR}/shaders/${id}/*.geom ${CMAKE_SOURCE_DIR}/shaders/${id}/*.frag
             ${CMAKE_SOURCE_DIR}/shaders/${id}/*.comp)
        if(NOT ARG_SOURCES)
            message(STATUS "technique ${id}: no sources in techniques/${id}/, left out")
            return()
        endif()
    endif()
    set(target gilab_technique_${id})
    add_library(${target} OBJECT ${ARG_SOURCES})
    target_link_libraries(${target} PUBLIC gilab_core)
    target_compile_options(${target} PRIVATE ${GILAB_WARNINGS})
    if(ARG_SHADERS)
        gilab_add_shaders(${target} SOURCES ${ARG_SHADERS})
    endif()
    set_property(GLOBAL APPEND PROPERTY GILAB_TECHNIQUE_TARGETS ${target})
endfunction()

# Links every self-registering OBJECT library (techniques, embedded shaders) into <target>.
function(gilab_link_plugins target)
    get_property(techniques GLOBAL PROPERTY GILAB_TECHNIQUE_TARGETS)
    foreach(t ${techniques})
        target_sources(${target} PRIVATE $<TARGET_OBJECTS:${t}>)
        target_link_libraries(${target} PRIVATE ${t})
    endforeach()
endfunction()
