"""Cuts a grown fuzz corpus to its most useful files (docs/fuzzing.md).

Usage, from the repository root, after a libFuzzer merge that wrote a control file:
    fuzz/target/x86_64-unknown-linux-gnu/release/TARGET -merge=1 -use_counters=0 -use_cmp=0 \
        -merge_control_file=CTL EMPTY_DIR fuzz/corpus/TARGET GROWN_DIR
    python3 fuzz/select_corpus.py CTL TARGET 200 1000000
Files already in fuzz/corpus/TARGET are kept; others are added greedily, the one covering the
most edges not yet covered first (the smaller on a tie), until no file adds an edge or the
corpus would exceed the file or byte cap.
"""
import sys, os, shutil
ctl, target, cap_files, cap_bytes = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
lines = open(ctl).read().split('\n')
n = int(lines[0]); files = lines[2:2+n]
cov = {}
for l in lines[2+n:]:
    if l.startswith('COV '):
        p = l.split(); cov[int(p[1])] = set(map(int, p[2:]))
forced = [i for i,f in enumerate(files) if f.startswith('fuzz/corpus/')]
covered = set(); nbytes = 0
for i in forced:
    covered |= cov.get(i, set()); nbytes += os.path.getsize(files[i])
all_edges = set().union(*cov.values())
chosen = []
cand = [i for i in range(n) if i not in forced]
while len(forced) + len(chosen) < cap_files:
    best, gain = None, 0
    for i in cand:
        g = len(cov.get(i, set()) - covered)
        if g > gain or (g == gain and g > 0 and os.path.getsize(files[i]) < os.path.getsize(files[best])):
            best, gain = i, g
    if best is None or gain == 0: break
    sz = os.path.getsize(files[best])
    if nbytes + sz > cap_bytes:
        cand.remove(best); continue
    chosen.append(best); cand.remove(best); covered |= cov[best]; nbytes += sz
print(f"{target}: forced {len(forced)}, chosen {len(chosen)}, edges {len(covered)}/{len(all_edges)}, bytes {nbytes}")
dest = f"fuzz/corpus/{target}"
for i in chosen:
    shutil.copy(files[i], os.path.join(dest, os.path.basename(files[i])))
