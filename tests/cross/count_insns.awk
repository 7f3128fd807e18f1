# Counts the instructions executed between the rs_probe_begin and rs_probe_end markers in a QEMU
# trace made with -singlestep -d exec,nochain (one "Trace ..." line per executed instruction, the
# function's symbol last). The first bracket is the empty baseline; the rest are measured ticks.
# Prints: brackets, baseline, mean and max instructions per measured bracket (baseline removed).
/^Trace/ {
  sym = $NF
  if (sym == "rs_probe_begin") { inside = 1; n = 0; next }
  if (sym == "rs_probe_end") {
    if (inside) {
      if (brackets == 0) { base = n } else { total += n; if (n > max) max = n }
      brackets++
    }
    inside = 0
    next
  }
  if (inside) n++
}
END {
  m = brackets - 1
  if (m < 1) { print "count_insns: no measured brackets"; exit 1 }
  printf "brackets %d baseline %d mean %.1f max %d\n", m, base, total / m - base, max - base
}
