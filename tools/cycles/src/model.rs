//! Cortex-M4 and Cortex-M7 cycle models of a Thumb-2 instruction stream.
//!
//! **Cortex-M4** (Arm, Cortex-M4 Processor Technical Reference Manual, r0p1, ARM DDI 0439:
//! section 3.3.1 "Cortex-M4 instructions", Table 3-1; section 3.3.2 "Load/store timings";
//! section 7.2.3 "FPU instruction set", Table 7-1). Zero-wait-state memory (no flash wait
//! states, no ART accelerator or cache effects) unless `wait_states` says otherwise.
//!
//! ```text
//! ALU, MOV, shifts, bit fields, compares, saturating, DSP, MUL/MLA/UMULL/SMLAL   1
//! SDIV, UDIV                               2..12 (early termination): `div` (default 12)
//! LDR/LDRB/LDRH/LDRSB/LDRSH, VLDR.32       2, or 1 when it follows a single load/store
//!                                            whose destination it does not use as address
//! STR*, VSTR.32                            1 (write buffer); 2 with a register offset
//!                                            unless it follows a single load/store
//! LDRD, STRD                               3 (1 + N, N = 2); VLDR.64, VSTR.64 3
//! LDM, STM, PUSH, POP, VLDM, VSTM, VPUSH, VPOP    1 + N (N words)
//! address from the previous data-processing result (3.3.2)   + 1
//! B, BL, BX, BLX, CBZ, CBNZ, B<cc>         1, + P when taken
//! LDR PC, POP {..., PC}, LDM {..., PC}     cost of the load, + P
//! TBB, TBH                                 2 + P
//! VADD, VSUB, VMUL, VNMUL, VABS, VNEG, VCMP, VCVT, VMOV, VMRS, VMSR   1
//! VMOV of two core registers (double or two singles)                   2
//! VMLA, VMLS, VNMLA, VNMLS, VFMA, VFMS, VFNMA, VFNMS                   3
//! VDIV, VSQRT                              14
//! IT                                       1 (an instruction it skips costs as if run)
//! P (pipeline refill) = 1, + 1 when the target is a 32-bit instruction that is not
//!   word-aligned (two fetches), + 1 for a register target (BX, POP/LDR PC, TBB/TBH:
//!   no early target speculation), + `wait_states`
//! every load pays `wait_states` more (data memory wait states)
//! ```
//!
//! **Cortex-M7: a dual-issue approximation.** Arm publishes no per-instruction cycle table
//! for the Cortex-M7, so this model is an approximation, not a TRM table: in-order, two
//! issue slots; two adjacent instructions of a block issue in one cycle when neither is a
//! multi-cycle instruction (divide, square root, LDM/STM/PUSH/POP, VLDM/VSTM, LDRD/STRD,
//! barriers), at most one is a load/store, at most one is a multiply or FPU operation, the
//! second does not read a register the first writes, and only the second may be a
//! branch. A load whose destination the next issue group reads costs one more cycle
//! (load-use). Divide and square root cost as on the M4, LDM/STM-class `1 + ceil(N/2)`
//! (64-bit bus), LDRD/STRD 1. Branches go through a bimodal predictor (2-bit counter and
//! last target per branch address): a correctly predicted branch costs its issue slot, a
//! mispredicted one `mispredict` more (default 4, assumed). Memory: TCM, zero wait states.

/// Register mask: bits 0-15 r0-r15, 16-47 s0-s31, bit 48 the flags.
pub type Regs = u64;
const PC: Regs = 1 << 15;

/// What an instruction is, for the models.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Single-cycle integer instruction (data processing, moves, compares, DSP).
    Alu,
    /// Multiply, multiply-accumulate, long multiply.
    Mul,
    /// SDIV, UDIV.
    Div,
    /// Single load (integer or VLDR.32).
    Load,
    /// Single store (integer or VSTR.32).
    Store,
    /// LDRD/STRD/VLDR.64/VSTR.64.
    Double,
    /// LDM/STM/PUSH/POP/VLDM/VSTM/VPUSH/VPOP of `n` words.
    Multi,
    /// FPU instruction of 1 cycle.
    Fp,
    /// VMOV between two core registers and a double (or two singles).
    FpMov2,
    /// VMLA and friends (3 cycles on the M4).
    FpMac,
    /// VDIV, VSQRT.
    FpDiv,
    /// B, BL, BX, BLX, CBZ, CBNZ, B<cc>.
    Branch,
    /// TBB, TBH.
    Table,
    /// IT.
    It,
    /// DMB, DSB, ISB and other serialising instructions.
    Barrier,
}

/// One decoded instruction.
#[derive(Debug, Clone)]
pub struct Insn {
    pub addr: u32,
    pub size: u32,
    pub text: String,
    pub kind: Kind,
    /// Words moved by a `Multi` (or 2 for a `Double`).
    pub n: u32,
    pub dst: Regs,
    pub src: Regs,
    /// Base and index registers of a load/store.
    pub addr_regs: Regs,
    /// Load/store with a register offset.
    pub reg_offset: bool,
    /// Writes the PC (a branch, `pop {pc}`, `ldr pc`).
    pub writes_pc: bool,
    /// The target is a register or loaded (no early speculation).
    pub indirect: bool,
}

const CONDS: [&str; 16] = [
    "eq", "ne", "cs", "hs", "cc", "lo", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt", "gt", "le",
];

fn is_cond(s: &str) -> bool {
    CONDS.contains(&s) || s == "al"
}

/// Register number of an operand token (`r0`..`r15`, `sb`, `sl`, `fp`, `ip`, `sp`, `lr`,
/// `pc`; `s0`..`s31`; `d0`..`d15` as two singles). Returns a mask.
fn reg_mask(tok: &str) -> Regs {
    let t = tok.trim().trim_end_matches('!').trim_end_matches('^');
    let core = |n: u32| -> Regs { 1 << n };
    match t {
        "sb" => return core(9),
        "sl" => return core(10),
        "fp" => return core(11),
        "ip" => return core(12),
        "sp" => return core(13),
        "lr" => return core(14),
        "pc" => return core(15),
        "apsr_nzcv" => return 1 << 48,
        _ => {}
    }
    let (p, num) = t.split_at(t.len().min(1));
    let Ok(n) = num.parse::<u32>() else {
        return 0;
    };
    match p {
        "r" if n < 16 => core(n),
        "s" if n < 32 => 1 << (16 + n),
        "d" if n < 16 => 3 << (16 + 2 * n),
        _ => 0,
    }
}

/// Expands a register list `{r4, r5, r7}` or `{s16-s31}` / `{d8-d15}`.
fn reg_list(list: &str) -> Regs {
    let mut m = 0;
    for part in list.split(',') {
        let part = part.trim();
        if let Some((a, b)) = part.split_once('-') {
            let (ma, mb) = (reg_mask(a), reg_mask(b));
            if ma == 0 || mb == 0 {
                continue;
            }
            let lo = ma.trailing_zeros();
            let hi = 63 - mb.leading_zeros();
            for i in lo..=hi {
                m |= 1 << i;
            }
        } else {
            m |= reg_mask(part);
        }
    }
    m
}

/// Registers named anywhere in `s` (outside braces handled by the caller).
fn regs_in(s: &str) -> Regs {
    s.split(|c: char| c == ',' || c == '[' || c == ']' || c.is_whitespace())
        .map(reg_mask)
        .fold(0, |a, b| a | b)
}

/// Mnemonic without the `.w`/`.n`/`.f32`… qualifiers and without a condition suffix
/// (IT blocks print `moveq`, `ldrne`, `bxeq`).
fn base_mnemonic(m: &str) -> String {
    let base = m.split('.').next().unwrap_or(m);
    // Mnemonics that end in letters that look like a condition.
    const KEEP: [&str; 12] = [
        "teq", "bls", "blt", "ble", "bhs", "bhi", "blo", "vcmpe", "umlal", "smlal", "bne", "beq",
    ];
    if KEEP.contains(&base) || base.len() <= 3 {
        return base.to_string();
    }
    let (head, tail) = base.split_at(base.len() - 2);
    if is_cond(tail) && head.len() >= 2 {
        return head.to_string();
    }
    base.to_string()
}

/// Decodes one instruction from QEMU's `in_asm` text (`mnemonic operands`).
pub fn decode(addr: u32, size: u32, mnemonic: &str, operands: &str) -> Insn {
    let m = mnemonic.to_ascii_lowercase();
    let ops = operands.to_ascii_lowercase();
    let base = base_mnemonic(&m);
    let mut insn = Insn {
        addr,
        size,
        text: format!("{mnemonic} {operands}").trim().to_string(),
        kind: Kind::Alu,
        n: 1,
        dst: 0,
        src: 0,
        addr_regs: 0,
        reg_offset: false,
        writes_pc: false,
        indirect: false,
    };
    let first = ops.split(',').next().unwrap_or("").trim().to_string();
    let braces = ops
        .find('{')
        .and_then(|a| ops[a..].find('}').map(|b| &ops[a + 1..a + b]))
        .unwrap_or("");
    let bracket = ops
        .find('[')
        .and_then(|a| ops[a..].find(']').map(|b| &ops[a + 1..a + b]))
        .unwrap_or("");
    let is_b = |b: &str| -> bool {
        matches!(b, "b" | "bl" | "bx" | "blx" | "cbz" | "cbnz")
            || (b.len() == 3 && b.starts_with('b') && is_cond(&b[1..]))
    };
    if base.starts_with("it") && base[2..].chars().all(|c| c == 't' || c == 'e') {
        insn.kind = Kind::It;
        return insn;
    }
    if is_b(&base) {
        insn.kind = Kind::Branch;
        insn.writes_pc = true;
        insn.indirect = base == "bx" || (base == "blx" && reg_mask(&first) != 0);
        if base == "bl" || base == "blx" {
            insn.dst = 1 << 14;
        }
        insn.src = if insn.indirect { reg_mask(&first) } else { 0 };
        if base == "cbz" || base == "cbnz" {
            insn.src = reg_mask(&first);
        }
        return insn;
    }
    if base == "tbb" || base == "tbh" {
        insn.kind = Kind::Table;
        insn.writes_pc = true;
        insn.indirect = true;
        insn.addr_regs = regs_in(bracket);
        return insn;
    }
    if matches!(
        base.as_str(),
        "dmb" | "dsb" | "isb" | "wfi" | "wfe" | "svc" | "bkpt"
    ) {
        insn.kind = Kind::Barrier;
        return insn;
    }
    if base.starts_with("vldm") || base == "vpop" || base.starts_with("vstm") || base == "vpush" {
        insn.kind = Kind::Multi;
        let list = reg_list(braces);
        insn.n = list.count_ones();
        if base.starts_with("vldm") || base == "vpop" {
            insn.dst = list;
        } else {
            insn.src = list;
        }
        insn.addr_regs = if base == "vpop" || base == "vpush" {
            1 << 13
        } else {
            reg_mask(&first)
        };
        return insn;
    }
    if base == "vldr" || base == "vstr" {
        let r = reg_mask(&first);
        insn.kind = if r.count_ones() == 2 {
            Kind::Double
        } else if base == "vldr" {
            Kind::Load
        } else {
            Kind::Store
        };
        insn.n = r.count_ones();
        if base == "vldr" {
            insn.dst = r;
        } else {
            insn.src = r;
        }
        insn.addr_regs = regs_in(bracket);
        return insn;
    }
    if base.starts_with('v') {
        let all = regs_in(&ops);
        let dst = reg_mask(&first);
        insn.dst = dst;
        insn.src = all & !dst;
        insn.kind = if base == "vdiv" || base == "vsqrt" {
            Kind::FpDiv
        } else if matches!(
            base.as_str(),
            "vmla" | "vmls" | "vnmla" | "vnmls" | "vfma" | "vfms" | "vfnma" | "vfnms"
        ) {
            insn.src |= dst;
            Kind::FpMac
        } else if base == "vmov" && (all & 0xffff).count_ones() == 2 {
            Kind::FpMov2
        } else {
            Kind::Fp
        };
        if base == "vcmp" || base == "vcmpe" {
            insn.src |= dst;
            insn.dst = 0;
        }
        if base == "vmrs" {
            insn.dst = if first == "apsr_nzcv" { 1 << 48 } else { dst };
        }
        return insn;
    }
    if base.starts_with("ldm") || base == "pop" || base.starts_with("stm") || base == "push" {
        let list = reg_list(braces);
        insn.kind = Kind::Multi;
        insn.n = list.count_ones();
        if base.starts_with("ldm") || base == "pop" {
            insn.dst = list;
            if list & PC != 0 {
                insn.writes_pc = true;
                insn.indirect = true;
            }
        } else {
            insn.src = list;
        }
        insn.addr_regs = if base == "pop" || base == "push" {
            1 << 13
        } else {
            reg_mask(&first)
        };
        return insn;
    }
    let is_ld = base.starts_with("ldr") || base.starts_with("ldaex") || base == "pld";
    let is_st = base.starts_with("str") || base.starts_with("stlex");
    if is_ld || is_st {
        let dbl = base == "ldrd" || base == "strd";
        insn.kind = match (dbl, is_ld) {
            (true, _) => Kind::Double,
            (false, true) => Kind::Load,
            (false, false) => Kind::Store,
        };
        insn.n = if dbl { 2 } else { 1 };
        insn.addr_regs = regs_in(bracket);
        insn.reg_offset = insn.addr_regs.count_ones() > 1;
        // Operands before the bracket: the transfer registers (and STREX's status).
        let before = ops.split('[').next().unwrap_or("");
        let regs = regs_in(before);
        if base == "pld" {
            insn.dst = 0;
        } else if is_ld {
            insn.dst = regs;
            if regs & PC != 0 {
                insn.writes_pc = true;
                insn.indirect = true;
            }
        } else {
            insn.src = regs;
            if base.starts_with("strex") {
                insn.dst = reg_mask(&first);
            }
        }
        // Writeback `[rn, #x]!` or post-index `[rn], #x` writes the base.
        let base_reg = reg_mask(bracket.split(',').next().unwrap_or(""));
        if ops.contains("]!") || ops.contains("], ") {
            insn.dst |= base_reg;
        }
        return insn;
    }
    if matches!(base.as_str(), "sdiv" | "udiv") {
        insn.kind = Kind::Div;
    } else if base.starts_with("mul")
        || base.starts_with("mla")
        || base.starts_with("mls")
        || base.starts_with("umull")
        || base.starts_with("smull")
        || base.starts_with("umlal")
        || base.starts_with("smlal")
        || base.starts_with("smla")
        || base.starts_with("smul")
        || base.starts_with("smmul")
        || base.starts_with("smmla")
        || base.starts_with("smuad")
        || base.starts_with("smlad")
    {
        insn.kind = Kind::Mul;
    }
    // Data processing: the first operand is the destination except for compares and
    // tests (long multiplies write two).
    let all = regs_in(&ops);
    let no_dst = matches!(base.as_str(), "cmp" | "cmn" | "tst" | "teq" | "nop");
    if no_dst {
        insn.src = all;
        insn.dst = 1 << 48;
    } else {
        let mut dst = reg_mask(&first);
        if matches!(
            base.as_str(),
            "umull" | "smull" | "umlal" | "smlal" | "umaal" | "smlalbb" | "smlald"
        ) {
            let second = ops.split(',').nth(1).unwrap_or("");
            dst |= reg_mask(second);
        }
        insn.dst = dst;
        insn.src = all & !dst;
        if base.ends_with('s') && base != "mls" {
            insn.dst |= 1 << 48;
        }
        if dst & PC != 0 {
            insn.writes_pc = true;
            insn.indirect = true;
        }
    }
    insn
}

/// Model parameters (one part: its clock and memory).
#[derive(Debug, Clone, Copy)]
pub struct Params {
    /// Cycles of SDIV/UDIV (2..12 on the M4, data dependent; default the worst case).
    pub div: u64,
    /// Wait states added to every load and to every pipeline refill.
    pub wait_states: u64,
    /// M7 branch misprediction penalty.
    pub mispredict: u64,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            div: 12,
            wait_states: 0,
            mispredict: 4,
        }
    }
}

fn single_ls(i: &Insn) -> bool {
    matches!(i.kind, Kind::Load | Kind::Store)
}

/// Cortex-M4 cycles of `insn` after `prev` in the same block, without the refill of a
/// taken branch (added by [`m4_refill`]).
pub fn m4_cost(insn: &Insn, prev: Option<&Insn>, p: &Params) -> u64 {
    let mem = matches!(
        insn.kind,
        Kind::Load | Kind::Store | Kind::Double | Kind::Multi | Kind::Table
    );
    let agu = match prev {
        Some(q) if mem && matches!(q.kind, Kind::Alu | Kind::Mul) => {
            u64::from(q.dst & insn.addr_regs & 0xffff != 0)
        }
        _ => 0,
    };
    let pipelined = match prev {
        Some(q) => single_ls(q) && single_ls(insn) && q.dst & insn.addr_regs == 0,
        None => false,
    };
    let is_load = matches!(
        insn.kind,
        Kind::Load | Kind::Double | Kind::Multi | Kind::Table
    ) && insn.dst != 0;
    let ws = if is_load { p.wait_states } else { 0 };
    let c = match insn.kind {
        Kind::Alu | Kind::Mul | Kind::Fp | Kind::It | Kind::Branch | Kind::Barrier => 1,
        Kind::FpMov2 => 2,
        Kind::FpMac => 3,
        Kind::FpDiv => 14,
        Kind::Div => p.div,
        Kind::Load => {
            if pipelined {
                1
            } else {
                2
            }
        }
        Kind::Store => {
            if insn.reg_offset && !pipelined {
                2
            } else {
                1
            }
        }
        Kind::Double => 1 + u64::from(insn.n),
        Kind::Multi => 1 + u64::from(insn.n),
        Kind::Table => 2,
    };
    c + agu + ws
}

/// Refill cycles P of a taken branch `last` to a target instruction of `target_size`
/// bytes at `target`.
pub fn m4_refill(last: &Insn, target: u32, target_size: u32, p: &Params) -> u64 {
    1 + u64::from(target_size == 4 && target % 4 == 2) + u64::from(last.indirect) + p.wait_states
}

fn m7_complex(i: &Insn) -> bool {
    matches!(
        i.kind,
        Kind::Div | Kind::FpDiv | Kind::Multi | Kind::Double | Kind::Barrier | Kind::Table
    ) || i.writes_pc && i.kind != Kind::Branch
}

fn m7_class(i: &Insn) -> u8 {
    match i.kind {
        Kind::Load | Kind::Store => 1,
        Kind::Mul | Kind::Fp | Kind::FpMac | Kind::FpMov2 => 2,
        _ => 0,
    }
}

/// Cortex-M7 cycles of a block's instructions (dual-issue approximation), without branch
/// prediction effects (added per execution).
pub fn m7_block(insns: &[Insn], p: &Params) -> u64 {
    let mut c = 0u64;
    let mut i = 0;
    let mut pending_load: Regs = 0;
    while i < insns.len() {
        let a = &insns[i];
        let mut group_reads = a.src | a.addr_regs;
        let mut group_load = if a.kind == Kind::Load { a.dst } else { 0 };
        let issued;
        if m7_complex(a) {
            c += match a.kind {
                Kind::Div => p.div,
                Kind::FpDiv => 14,
                Kind::Multi => 1 + u64::from(a.n).div_ceil(2),
                _ => 1,
            };
            issued = 1;
            if a.kind == Kind::Multi || a.kind == Kind::Double {
                group_load = a.dst & 0xffff_ffff_ffff;
            }
        } else {
            c += 1;
            let pair = insns.get(i + 1).is_some_and(|b| {
                !m7_complex(b)
                    && a.kind != Kind::Branch
                    && !(m7_class(a) != 0 && m7_class(a) == m7_class(b))
                    && (b.src | b.addr_regs) & a.dst & !(1 << 48) == 0
            });
            if pair {
                let b = &insns[i + 1];
                group_reads |= b.src | b.addr_regs;
                if b.kind == Kind::Load {
                    group_load |= b.dst;
                }
                issued = 2;
            } else {
                issued = 1;
            }
        }
        if pending_load & group_reads != 0 {
            c += 1;
        }
        pending_load = group_load;
        c += if group_load != 0 { p.wait_states } else { 0 };
        i += issued;
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    fn d(m: &str, o: &str) -> Insn {
        decode(0x100, 2, m, o)
    }

    #[test]
    fn decodes_classes_and_registers() {
        let i = d("ldr", "r0, [r1, #4]");
        assert_eq!(i.kind, Kind::Load);
        assert_eq!(i.dst, 1);
        assert_eq!(i.addr_regs, 2);
        let i = d("pop", "{r4, r5, r7, pc}");
        assert_eq!((i.kind, i.n, i.writes_pc), (Kind::Multi, 4, true));
        let i = d("vpush", "{d8, d9, d10}");
        assert_eq!(i.n, 6);
        let i = d("vldmia", "r0!, {s0-s7}");
        assert_eq!(i.n, 8);
        assert_eq!(d("vdiv.f32", "s0, s0, s1").kind, Kind::FpDiv);
        assert_eq!(d("vfma.f32", "s0, s1, s2").kind, Kind::FpMac);
        assert_eq!(d("bls", "#0x40").kind, Kind::Branch);
        assert_eq!(d("bl", "#0x40").kind, Kind::Branch);
        assert_eq!(d("bxeq", "lr").kind, Kind::Branch);
        assert!(d("bx", "lr").indirect);
        assert_eq!(d("ite", "eq").kind, Kind::It);
        assert_eq!(d("moveq", "r0, r1").kind, Kind::Alu);
        assert_eq!(d("ldrne", "r0, [r1]").kind, Kind::Load);
        assert_eq!(d("umull", "r0, r1, r2, r3").dst, 3);
        assert_eq!(d("vmov", "r0, r1, d0").kind, Kind::FpMov2);
        assert_eq!(d("ldrd", "r0, r1, [r2]").kind, Kind::Double);
        assert_eq!(d("cmp", "r0, r1").dst, 1 << 48);
    }

    /// The TRM's pipelining examples (3.3.2): `LDR R0,[R1]; LDR R1,[R2]` three cycles,
    /// `LDR R0,[R1,R5]; LDR R1,[R2]; LDR R2,[R3,#4]` four; a load whose address is the
    /// previous load's result is not pipelined; an address from the previous ALU result
    /// stalls one cycle.
    #[test]
    fn m4_load_pipelining_follows_the_trm_examples() {
        let p = Params::default();
        let seq = |v: &[Insn]| -> u64 {
            (0..v.len())
                .map(|k| m4_cost(&v[k], k.checked_sub(1).map(|j| &v[j]), &p))
                .sum()
        };
        assert_eq!(seq(&[d("ldr", "r0, [r1]"), d("ldr", "r1, [r2]")]), 3);
        assert_eq!(
            seq(&[
                d("ldr", "r0, [r1, r5]"),
                d("ldr", "r1, [r2]"),
                d("ldr", "r2, [r3, #4]")
            ]),
            4
        );
        assert_eq!(seq(&[d("ldr", "r0, [r1]"), d("ldr", "r1, [r0]")]), 4);
        assert_eq!(seq(&[d("adds", "r0, #4"), d("ldr", "r1, [r0]")]), 4);
        assert_eq!(seq(&[d("ldm", "r0, {r1, r2, r3, r4}")]), 5);
    }

    #[test]
    fn m4_refill_counts_alignment_and_register_targets() {
        let p = Params::default();
        assert_eq!(m4_refill(&d("bne", "#0x40"), 0x40, 2, &p), 1);
        assert_eq!(m4_refill(&d("bne", "#0x42"), 0x42, 4, &p), 2);
        assert_eq!(m4_refill(&d("bx", "lr"), 0x40, 2, &p), 2);
    }

    #[test]
    fn m7_pairs_independent_alu_and_load_but_not_two_loads() {
        let p = Params::default();
        assert_eq!(m7_block(&[d("adds", "r0, #1"), d("adds", "r1, #1")], &p), 1);
        assert_eq!(m7_block(&[d("adds", "r0, #1"), d("adds", "r1, r0")], &p), 2);
        assert_eq!(
            m7_block(&[d("ldr", "r0, [r2]"), d("ldr", "r1, [r3]")], &p),
            2
        );
        assert_eq!(
            m7_block(&[d("ldr", "r0, [r2]"), d("adds", "r1, #1")], &p),
            1
        );
        // Load-use: the next group reads the loaded register.
        assert_eq!(
            m7_block(
                &[d("ldr", "r0, [r2]"), d("nop", ""), d("adds", "r1, r0")],
                &p
            ),
            3
        );
        assert_eq!(m7_block(&[d("vdiv.f32", "s0, s0, s1")], &p), 14);
    }
}
