//! Aggregates QEMU's `-d in_asm,exec,nochain` log: every executed translation block (TB)
//! with its instructions, attributed to the regions between the firmware's
//! `faint_cycles_begin` and `faint_cycles_end` calls, costed by the models.
//!
//! The log has two kinds of lines this reads. `in_asm` prints a TB's instructions when it
//! is translated (`0x00000404:  480e  ldr r0, [pc, #0x38]`); the TB runs right after, so
//! the next `exec` line (`Trace 0: 0x7f.. [cs_base/pc/flags/cflags] symbol`) names the host
//! address of that translation, which identifies it in every later `Trace` line. With
//! `nochain` every TB execution goes through the main loop and is logged. A
//! `Stopped execution of TB chain before` line means the TB just logged did not run
//! (icount budget or an interrupt request). A TB re-translated with `CF_LAST_IO`
//! (icount's I/O rule) ends the previous TB early: the previous TB is then cut at the
//! new TB's address.

use std::collections::HashMap;

use crate::model::{decode, m4_cost, m4_refill, m7_block, Insn, Params};

/// `CF_LAST_IO` of QEMU's TB `cflags`.
const CF_LAST_IO: u32 = 0x0000_8000;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Marker {
    None,
    Begin,
    End,
}

struct Block {
    insns: Vec<Insn>,
    start: u32,
    end: u32,
    m4: u64,
    m7: u64,
    marker: Marker,
}

impl Block {
    fn new(insns: Vec<Insn>, symbol: &str, p: &Params) -> Self {
        let start = insns.first().map_or(0, |i| i.addr);
        let end = insns.last().map_or(0, |i| i.addr + i.size);
        let (m4, m7) = costs(&insns, p);
        let marker = match symbol {
            "faint_cycles_begin" => Marker::Begin,
            "faint_cycles_end" => Marker::End,
            _ => Marker::None,
        };
        Block {
            insns,
            start,
            end,
            m4,
            m7,
            marker,
        }
    }
}

fn costs(insns: &[Insn], p: &Params) -> (u64, u64) {
    let m4 = (0..insns.len())
        .map(|k| m4_cost(&insns[k], k.checked_sub(1).map(|j| &insns[j]), p))
        .sum();
    (m4, m7_block(insns, p))
}

/// Totals of one region.
#[derive(Debug, Default, Clone)]
pub struct Totals {
    pub instructions: u64,
    pub blocks: u64,
    pub m4: u64,
    pub m7: u64,
    /// Executions per block id (only with `hot`).
    pub per_block: HashMap<usize, (u64, u64)>,
    /// Digest of the executed instruction stream (only with `streams`): FNV-1a (64-bit)
    /// over the address of every executed instruction, in execution order, so it does
    /// not depend on where QEMU cut the stream into blocks.
    pub stream: u64,
}

/// FNV-1a (64-bit) offset basis and prime.
const FNV_BASIS: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

/// Folds the 4 little-endian bytes of `addr` into an FNV-1a digest.
fn fnv_addr(mut h: u64, addr: u32) -> u64 {
    for b in addr.to_le_bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(FNV_PRIME);
    }
    h
}

/// The aggregator: feed it the log line by line.
pub struct Tracer {
    p: Params,
    hot: bool,
    /// Digest each region's executed instruction stream ([`Totals::stream`]).
    pub streams: bool,
    blocks: Vec<Block>,
    by_ptr: HashMap<u64, usize>,
    asm: Vec<Insn>,
    in_block: bool,
    /// The last TB logged, not yet costed: (block, its pc).
    pending: Option<usize>,
    active: bool,
    predictor: HashMap<u32, (u8, u32)>,
    /// The block the pending one was entered from by falling through (no branch).
    fall: Option<usize>,
    /// Cost corrections of a fall-through pair (a block QEMU split, see [`Tracer::seam`]).
    seams: HashMap<(usize, usize), (i64, i64)>,
    pub regions: Vec<Totals>,
    /// Trace lines whose translation was never printed, and other oddities.
    pub unknown: u64,
    pub lines: u64,
}

impl Tracer {
    pub fn new(p: Params, hot: bool) -> Self {
        Tracer {
            p,
            hot,
            streams: false,
            blocks: Vec::new(),
            by_ptr: HashMap::new(),
            asm: Vec::new(),
            in_block: false,
            pending: None,
            active: false,
            predictor: HashMap::new(),
            fall: None,
            seams: HashMap::new(),
            regions: Vec::new(),
            unknown: 0,
            lines: 0,
        }
    }

    /// Instructions of block `id` as text (for hot-block listings and llvm-mca).
    pub fn block_text(&self, id: usize) -> (u32, Vec<String>) {
        let b = &self.blocks[id];
        (b.start, b.insns.iter().map(|i| i.text.clone()).collect())
    }

    /// M4 and M7 cycles of one execution of block `id` without branch effects.
    pub fn block_cost(&self, id: usize) -> (u64, u64, usize) {
        let b = &self.blocks[id];
        (b.m4, b.m7, b.insns.len())
    }

    /// M4 cycles of block `id` without its last instruction (a loop body without its
    /// branch, as llvm-mca sees it).
    pub fn body_m4(&self, id: usize) -> u64 {
        let b = &self.blocks[id];
        costs(&b.insns[..b.insns.len().saturating_sub(1)], &self.p).0
    }

    /// Feeds one log line.
    pub fn line(&mut self, l: &str) {
        self.lines += 1;
        if let Some(rest) = l.strip_prefix("Trace ") {
            self.in_block = false;
            self.exec(rest);
        } else if l.starts_with("0x") {
            if let Some(i) = parse_insn(l) {
                self.in_block = true;
                self.asm.push(i);
            }
        } else if l.starts_with("Stopped execution of TB chain") {
            self.pending = None;
            self.fall = None;
        }
    }

    fn exec(&mut self, rest: &str) {
        // `0: 0x7f93f0000100 [00800408/00000400/00000110/ff020200] Reset`
        let Some((_, rest)) = rest.split_once(": ") else {
            self.unknown += 1;
            return;
        };
        let Some((ptr, rest)) = rest.split_once(" [") else {
            self.unknown += 1;
            return;
        };
        let Some((fields, symbol)) = rest.split_once(']') else {
            self.unknown += 1;
            return;
        };
        let symbol = symbol.trim();
        let ptr = u64::from_str_radix(ptr.trim_start_matches("0x"), 16).unwrap_or(0);
        let mut f = fields.split('/');
        let _cs = f.next();
        let pc = f
            .next()
            .and_then(|s| u32::from_str_radix(s, 16).ok())
            .unwrap_or(0);
        let _flags = f.next();
        let cflags = f
            .next()
            .and_then(|s| u32::from_str_radix(s, 16).ok())
            .unwrap_or(0);
        let id = if !self.asm.is_empty() {
            let insns = std::mem::take(&mut self.asm);
            if insns[0].addr != pc {
                self.unknown += 1;
            }
            let b = Block::new(insns, symbol, &self.p);
            self.blocks.push(b);
            let id = self.blocks.len() - 1;
            self.by_ptr.insert(ptr, id);
            id
        } else if let Some(&id) = self.by_ptr.get(&ptr) {
            id
        } else {
            self.unknown += 1;
            self.pending = None;
            self.fall = None;
            return;
        };
        // The previous TB ran (this one follows it): cost it, then apply its marker.
        if let Some(prev) = self.pending.take() {
            self.cost(prev, pc, id, cflags);
            match self.blocks[prev].marker {
                Marker::Begin => {
                    self.active = true;
                    self.regions.push(Totals {
                        stream: FNV_BASIS,
                        ..Totals::default()
                    });
                }
                Marker::End => self.active = false,
                Marker::None => {}
            }
        }
        self.pending = Some(id);
    }

    /// Cycles to add when `second` runs right after `first` by falling through: QEMU ends
    /// a block early (icount budget, I/O, page end) at points that depend on the run, so
    /// the pair is costed as the one block it is (load pipelining, M7 pairing across the
    /// seam), which keeps the totals independent of where QEMU split it.
    fn seam(&mut self, first: usize, second: usize) -> (i64, i64) {
        if let Some(&d) = self.seams.get(&(first, second)) {
            return d;
        }
        let (a, b) = (&self.blocks[first], &self.blocks[second]);
        let joint: Vec<Insn> = a.insns.iter().chain(&b.insns).cloned().collect();
        let (m4, m7) = costs(&joint, &self.p);
        let d = (
            m4 as i64 - a.m4 as i64 - b.m4 as i64,
            m7 as i64 - a.m7 as i64 - b.m7 as i64,
        );
        self.seams.insert((first, second), d);
        d
    }

    fn cost(&mut self, prev: usize, next_pc: u32, next: usize, next_cflags: u32) {
        let fell_from = self.fall.take();
        let b = &self.blocks[prev];
        let Some(last) = b.insns.last() else {
            return;
        };
        if !last.writes_pc && next_pc == b.end {
            self.fall = Some(prev);
        }
        // M7 branch prediction, trained everywhere (also outside regions).
        let taken = last.writes_pc && next_pc != b.end;
        let mut m7_extra = 0;
        if last.writes_pc {
            let e = self.predictor.entry(last.addr).or_insert((1, 0));
            let predicted = e.0 >= 2;
            let right = if taken {
                predicted && e.1 == next_pc
            } else {
                !predicted
            };
            if !right {
                m7_extra = self.p.mispredict + self.p.wait_states;
            }
            e.0 = if taken {
                (e.0 + 1).min(3)
            } else {
                e.0.saturating_sub(1)
            };
            if taken {
                e.1 = next_pc;
            }
        }
        if !self.active || b.marker != Marker::None {
            return;
        }
        let (n, m4, m7) = if next_cflags & CF_LAST_IO != 0 && b.start < next_pc && next_pc < b.end {
            let k = b.insns.iter().take_while(|i| i.addr < next_pc).count();
            let (m4, m7) = costs(&b.insns[..k], &self.p);
            (k as u64, m4, m7)
        } else {
            let refill = if taken {
                let size = self.blocks[next].insns.first().map_or(2, |i| i.size);
                m4_refill(last, next_pc, size, &self.p)
            } else {
                0
            };
            (b.insns.len() as u64, b.m4 + refill, b.m7 + m7_extra)
        };
        let (d4, d7) = match fell_from {
            Some(f) if self.blocks[f].marker == Marker::None => self.seam(f, prev),
            _ => (0, 0),
        };
        let r = self
            .regions
            .last_mut()
            .expect("a region is open when active");
        r.instructions += n;
        r.blocks += 1;
        if self.streams {
            for i in &self.blocks[prev].insns[..n as usize] {
                r.stream = fnv_addr(r.stream, i.addr);
            }
        }
        r.m4 = r.m4.wrapping_add(m4).wrapping_add_signed(d4);
        r.m7 = r.m7.wrapping_add(m7).wrapping_add_signed(d7);
        if self.hot {
            let e = r.per_block.entry(prev).or_insert((0, 0));
            e.0 += 1;
            e.1 += m4;
        }
    }
}

/// `0x00000404:  480e       ldr      r0, [pc, #0x38]` (16-bit) or
/// `0x00000400:  f069 fa38  bl       #0x69874` (32-bit).
fn parse_insn(l: &str) -> Option<Insn> {
    let (addr, rest) = l.split_once(':')?;
    let addr = u32::from_str_radix(addr.trim_start_matches("0x"), 16).ok()?;
    let mut rest = rest.trim_start();
    let mut size = 0;
    loop {
        let tok = rest.split_whitespace().next()?;
        if tok.len() == 4 && tok.bytes().all(|c| c.is_ascii_hexdigit()) && size < 4 {
            size += 2;
            rest = rest[tok.len()..].trim_start();
        } else {
            break;
        }
    }
    if size == 0 {
        return None;
    }
    let (mnemonic, operands) = match rest.split_once(char::is_whitespace) {
        Some((m, o)) => (m, o.trim()),
        None => (rest.trim(), ""),
    };
    Some(decode(addr, size, mnemonic, operands))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hand-written log: a loop block executed three times (taken twice), inside a
    /// region; the instructions and the M4 cycles follow from the TRM costs.
    #[test]
    fn attributes_blocks_between_markers() {
        let log = "\
IN: faint_cycles_begin
0x00000100:  bf00       nop
0x00000102:  4770       bx       lr

Trace 0: 0x7f0000000100 [00000000/00000100/00000110/ff020200] faint_cycles_begin
IN: loop
0x00000200:  3801       subs     r0, #1
0x00000202:  d1fd       bne      #0x200

Trace 0: 0x7f0000000200 [00000000/00000200/00000110/ff020200] loop
Trace 0: 0x7f0000000200 [00000000/00000200/00000110/ff020200] loop
Trace 0: 0x7f0000000200 [00000000/00000200/00000110/ff020200] loop
IN: after
0x00000204:  f000 f800  bl       #0x300

Trace 0: 0x7f0000000300 [00000000/00000204/00000110/ff020200] after
IN: faint_cycles_end
0x00000300:  4770       bx       lr

Trace 0: 0x7f0000000400 [00000000/00000300/00000110/ff020200] faint_cycles_end
";
        let mut t = Tracer::new(Params::default(), false);
        for l in log.lines() {
            t.line(l);
        }
        assert_eq!(t.unknown, 0);
        assert_eq!(t.regions.len(), 1);
        let r = &t.regions[0];
        // 3 x (subs, bne) + bl
        assert_eq!(r.instructions, 7);
        // subs 1 + bne 1 (+ P = 1 when taken, twice) three times; bl 1 + P = 1.
        assert_eq!(r.m4, 3 * 2 + 2 + 2);
    }

    /// A block QEMU split in two (no branch between the halves) costs what the whole
    /// block costs: the second load still pipelines with the first.
    #[test]
    fn a_split_block_costs_the_whole_block() {
        let run = |split: bool| -> u64 {
            let mut t = Tracer::new(Params::default(), false);
            let mut log = vec![
                "IN: faint_cycles_begin",
                "0x00000100:  4770       bx       lr",
                "Trace 0: 0x10 [00000000/00000100/00000110/ff020200] faint_cycles_begin",
            ];
            if split {
                log.extend([
                    "IN: x",
                    "0x00000200:  6820       ldr      r0, [r4]",
                    "Trace 0: 0x20 [00000000/00000200/00000110/ff020201] x",
                    "IN: x",
                    "0x00000202:  6861       ldr      r1, [r4, #4]",
                    "0x00000204:  e000       b        #0x208",
                    "Trace 0: 0x28 [00000000/00000202/00000110/ff020200] x",
                ]);
            } else {
                log.extend([
                    "IN: x",
                    "0x00000200:  6820       ldr      r0, [r4]",
                    "0x00000202:  6861       ldr      r1, [r4, #4]",
                    "0x00000204:  e000       b        #0x208",
                    "Trace 0: 0x20 [00000000/00000200/00000110/ff020200] x",
                ]);
            }
            log.extend([
                "IN: faint_cycles_end",
                "0x00000208:  4770       bx       lr",
                "Trace 0: 0x30 [00000000/00000208/00000110/ff020200] faint_cycles_end",
            ]);
            for l in log {
                t.line(l);
            }
            assert_eq!(t.regions[0].instructions, 3);
            t.regions[0].m4
        };
        // 2 + 1 (pipelined) + b (1 + P = 1)
        assert_eq!(run(false), 5);
        assert_eq!(run(true), 5);
    }

    /// The stream digest is the executed addresses' FNV-1a, whether QEMU cut a block in
    /// two or not.
    #[test]
    fn the_stream_digest_ignores_block_splits() {
        let run = |split: bool| -> u64 {
            let mut t = Tracer::new(Params::default(), false);
            t.streams = true;
            let mut log = vec![
                "IN: faint_cycles_begin",
                "0x00000100:  4770       bx       lr",
                "Trace 0: 0x10 [00000000/00000100/00000110/ff020200] faint_cycles_begin",
            ];
            if split {
                log.extend([
                    "IN: x",
                    "0x00000200:  6820       ldr      r0, [r4]",
                    "Trace 0: 0x20 [00000000/00000200/00000110/ff020201] x",
                    "IN: x",
                    "0x00000202:  6861       ldr      r1, [r4, #4]",
                    "0x00000204:  e000       b        #0x208",
                    "Trace 0: 0x28 [00000000/00000202/00000110/ff020200] x",
                ]);
            } else {
                log.extend([
                    "IN: x",
                    "0x00000200:  6820       ldr      r0, [r4]",
                    "0x00000202:  6861       ldr      r1, [r4, #4]",
                    "0x00000204:  e000       b        #0x208",
                    "Trace 0: 0x20 [00000000/00000200/00000110/ff020200] x",
                ]);
            }
            log.extend([
                "IN: faint_cycles_end",
                "0x00000208:  4770       bx       lr",
                "Trace 0: 0x30 [00000000/00000208/00000110/ff020200] faint_cycles_end",
            ]);
            for l in log {
                t.line(l);
            }
            t.regions[0].stream
        };
        // The reference: FNV-1a written out over the bytes of 0x200, 0x202, 0x204.
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in [0x00, 0x02, 0, 0, 0x02, 0x02, 0, 0, 0x04, 0x02, 0, 0] {
            h ^= b;
            h = h.wrapping_mul(0x100_0000_01b3);
        }
        assert_eq!(run(false), h);
        assert_eq!(run(true), h);
    }

    #[test]
    fn a_stopped_tb_is_not_counted() {
        let mut t = Tracer::new(Params::default(), false);
        for l in [
            "IN: faint_cycles_begin",
            "0x00000100:  4770       bx       lr",
            "Trace 0: 0x10 [00000000/00000100/00000110/ff020200] faint_cycles_begin",
            "IN: x",
            "0x00000200:  3801       subs     r0, #1",
            "0x00000202:  e7fd       b        #0x200",
            "Trace 0: 0x20 [00000000/00000200/00000110/ff020200] x",
            "Trace 0: 0x10 [00000000/00000100/00000110/ff020200] faint_cycles_begin",
            "Stopped execution of TB chain before 0x10 [00000100] faint_cycles_begin",
            "Trace 0: 0x20 [00000000/00000200/00000110/ff020200] x",
            "Stopped execution of TB chain before 0x20 [00000200] x",
            "Trace 0: 0x20 [00000000/00000200/00000110/ff020200] x",
            "IN: faint_cycles_end",
            "0x00000300:  4770       bx       lr",
            "Trace 0: 0x30 [00000000/00000300/00000110/ff020200] faint_cycles_end",
        ] {
            t.line(l);
        }
        assert_eq!(t.regions.len(), 1);
        assert_eq!(t.regions[0].instructions, 4);
    }
}
