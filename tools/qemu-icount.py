#!/usr/bin/env python3
"""Guest instructions executed, from a qemu-user log (no TCG plugins needed).

    qemu-aarch64 -d in_asm,exec,nochain -D LOG prog
    python3 tools/qemu-icount.py LOG

in_asm prints each translated block once ("IN:" then one line per guest
instruction, "0x<addr>:  <encoding>  <mnemonic>"); exec prints a "Trace" line
each time a block runs ("Trace 0: 0x<host tb> [<cs_base>/<pc>/<flags>...] ...").
With nochain every block execution goes through the main loop and is logged,
so the count is sum over Trace lines of the instruction count of the block
translated at that pc. A pc translated again (e.g. after a TB flush) takes the
size of its latest translation before the execution. Prints the total.
"""
import re
import sys

INSN = re.compile(r"^0x([0-9a-f]+):\s")
TRACE = re.compile(r"^Trace \d+: 0x[0-9a-f]+ \[[0-9a-f]+/([0-9a-f]+)/")


def count(path):
    size = {}          # block start pc -> instructions in its latest translation
    total = 0
    blocks = 0
    unknown = 0
    cur_pc = None      # pc of the block whose in_asm listing is being read
    cur_n = 0
    in_block = False
    with open(path, "r", errors="replace") as f:
        for line in f:
            if line.startswith("Trace "):
                if in_block:
                    size[cur_pc] = cur_n
                    in_block = False
                m = TRACE.match(line)
                if not m:
                    continue
                pc = int(m.group(1), 16)
                n = size.get(pc)
                if n is None:
                    unknown += 1
                    continue
                total += n
                blocks += 1
            elif line.startswith("IN:"):
                if in_block:
                    size[cur_pc] = cur_n
                in_block = True
                cur_pc = None
                cur_n = 0
            elif in_block:
                m = INSN.match(line)
                if m:
                    if cur_pc is None:
                        cur_pc = int(m.group(1), 16)
                    cur_n += 1
                elif line.strip() == "" and cur_pc is not None:
                    size[cur_pc] = cur_n
                    in_block = False
    if in_block and cur_pc is not None:
        size[cur_pc] = cur_n
    return total, blocks, unknown


def main():
    if len(sys.argv) != 2:
        sys.stderr.write("usage: qemu-icount.py QEMU_LOG\n")
        return 2
    total, blocks, unknown = count(sys.argv[1])
    if unknown:
        sys.stderr.write("qemu-icount: %d block executions with no in_asm listing\n" % unknown)
    sys.stderr.write("qemu-icount: %d block executions\n" % blocks)
    print(total)
    return 0


if __name__ == "__main__":
    sys.exit(main())
