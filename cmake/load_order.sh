#!/bin/sh
# Prints the N shared libraries that LIBRARY loads (ldd) with the most symbol relocations, most
# first, leaving out the C and C++ runtimes (their place in the search order stays as it is).
# A library's symbol relocations: its relocation bytes (RELASZ + PLTRELSZ, 24 bytes each) less its
# relative relocations (RELACOUNT), which need no lookup.
#   load_order.sh LIBRARY N
lib=$1 n=$2
ldd "$lib" | sed -n 's/.*=> \(\/[^ ]*\) .*/\1/p' | while read -r dep; do
  readelf -dW "$dep" 2>/dev/null | awk -v dep="$dep" '
    /\((RELASZ|PLTRELSZ)\)/ { bytes += $3 }
    /\(RELACOUNT\)/ { relative = $3 }
    END { print int(bytes / 24) - relative, dep }'
done | sort -rn | grep -v -E '/(libc|libm|libstdc\+\+|libgcc_s|libpthread|libdl|ld-linux[^/]*)\.so' |
  head -n "$n" | cut -d' ' -f2
