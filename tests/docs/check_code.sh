#!/bin/sh
# The code blocks of the documentation that come from source files, checked
# against those files:
#   check_code.sh ROOT DOC.md...
# A fenced block whose line above is
#   <!-- code: PATH -->          must be the whole of ROOT/PATH, line for line;
#   <!-- code: PATH excerpt -->  must be lines of ROOT/PATH that follow each other.
# Every ```c and ```cpp block of the documents given must carry one of the two,
# so that no code in them goes unchecked. Prints each block that fails, with its
# document and line and the first line that differs, and exits 1; exits 0 when
# every block matches.
root="$1"
shift
status=0
for doc in "$@"; do
    awk -v root="$root" '
    # Loads ROOT/path into src[path, 1 .. n]; returns n, or -1 when unreadable.
    function load(path,    line, n, r) {
        if (path in loaded)
            return loaded[path]
        n = 0
        while ((r = (getline line < (root "/" path))) > 0)
            src[path, ++n] = line
        close(root "/" path)
        loaded[path] = r < 0 ? -1 : n
        return loaded[path]
    }
    function fail(msg) {
        printf "%s:%d: %s\n", FILENAME, start, msg
        bad = 1
    }
    # The block against its file: equal, or (excerpt) found in it.
    function check(    n, i, j, best, best_at) {
        n = load(path)
        if (n < 0) {
            fail("cannot read " path)
            return
        }
        if (!excerpt) {
            for (i = 1; i <= count && i <= n; ++i)
                if (block[i] != src[path, i]) {
                    fail("differs from " path " at its line " i ":\n  doc:  " block[i] \
                         "\n  file: " src[path, i])
                    return
                }
            if (count != n)
                fail("has " count " lines, " path " has " n)
            return
        }
        best = -1
        for (i = 0; i + count <= n; ++i) {
            for (j = 1; j <= count && block[j] == src[path, i + j]; ++j)
                ;
            if (j > count)
                return
            if (j - 1 > best) {
                best = j - 1
                best_at = j
            }
        }
        if (best < 0)
            fail("is longer than " path)
        else
            fail("is not an excerpt of " path "; its line " best_at " does not follow:\n  " \
                 block[best_at])
    }
    inside {
        if ($0 ~ /^```[ \t]*$/) {
            inside = 0
            if (path != "")
                check()
        } else {
            block[++count] = $0
        }
        prev = $0
        next
    }
    /^```/ {
        inside = 1
        count = 0
        start = FNR
        path = ""
        excerpt = 0
        if (prev ~ /^<!-- code: [^ ]+( excerpt)? -->$/) {
            path = prev
            sub(/^<!-- code: /, "", path)
            sub(/ -->$/, "", path)
            if (path ~ / excerpt$/) {
                excerpt = 1
                sub(/ excerpt$/, "", path)
            }
        } else if ($0 ~ /^```(c|cpp)[ \t]*$/) {
            fail("a code block without <!-- code: PATH --> or <!-- code: PATH excerpt --> above it")
        }
        prev = $0
        next
    }
    { prev = $0 }
    END {
        if (inside)
            fail("a code block that is never closed")
        exit bad + 0
    }' "$root/$doc" || status=1
done
if [ "$status" -eq 0 ]; then
    echo "check_code: the code blocks of $* match their files"
fi
exit "$status"
