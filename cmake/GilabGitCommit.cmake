# Writes ${OUT} (gilab::build::kGitCommit) from `git describe` at build time, so every build
# records the commit it was built from (plus "-dirty" for uncommitted changes), not the one it
# was configured at. The file is only rewritten when the text changes.
execute_process(COMMAND git rev-parse --short=12 HEAD WORKING_DIRECTORY ${SRC}
                OUTPUT_VARIABLE commit OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT commit)
    set(commit "unknown")
else()
    execute_process(COMMAND git status --porcelain --untracked-files=no WORKING_DIRECTORY ${SRC}
                    OUTPUT_VARIABLE dirty OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(dirty)
        set(commit "${commit}-dirty")
    endif()
endif()
set(text "#pragma once\n// Generated at build time by cmake/GilabGitCommit.cmake.\nnamespace gilab::build {\ninline constexpr const char* kGitCommit = \"${commit}\";\n}  // namespace gilab::build\n")
if(EXISTS ${OUT})
    file(READ ${OUT} old)
endif()
if(NOT "${old}" STREQUAL "${text}")
    file(WRITE ${OUT} "${text}")
endif()
