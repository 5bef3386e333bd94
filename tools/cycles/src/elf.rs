//! Section sizes and symbols of a 32-bit little-endian ELF image (the firmware).

/// One section.
#[derive(Debug, Clone)]
pub struct Section {
    pub name: String,
    pub size: u64,
    pub alloc: bool,
}

/// One sized symbol (function or object).
#[derive(Debug, Clone)]
pub struct Symbol {
    pub name: String,
    pub size: u64,
    pub section: usize,
}

fn u16le(b: &[u8], o: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(o..o + 2)?.try_into().ok()?))
}

fn u32le(b: &[u8], o: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(o..o + 4)?.try_into().ok()?))
}

fn cstr(b: &[u8], o: usize) -> String {
    let s = b.get(o..).unwrap_or(&[]);
    let end = s.iter().position(|&c| c == 0).unwrap_or(s.len());
    String::from_utf8_lossy(&s[..end]).into_owned()
}

/// Sections and sized symbols, or why the file is not a 32-bit little-endian ELF.
pub fn read(b: &[u8]) -> Result<(Vec<Section>, Vec<Symbol>), String> {
    if b.get(..4) != Some(b"\x7fELF") || b.get(4) != Some(&1) || b.get(5) != Some(&1) {
        return Err("not a 32-bit little-endian ELF file".into());
    }
    let bad = || "truncated ELF header or section table".to_string();
    let shoff = u32le(b, 0x20).ok_or_else(bad)? as usize;
    let shentsize = u16le(b, 0x2e).ok_or_else(bad)? as usize;
    let shnum = u16le(b, 0x30).ok_or_else(bad)? as usize;
    let shstrndx = u16le(b, 0x32).ok_or_else(bad)? as usize;
    let sh = |i: usize, f: usize| u32le(b, shoff + i * shentsize + f).ok_or_else(bad);
    let stroff = sh(shstrndx, 16)? as usize;
    let mut sections = Vec::with_capacity(shnum);
    let mut symtab = None;
    for i in 0..shnum {
        let ty = sh(i, 4)?;
        let flags = sh(i, 8)?;
        sections.push(Section {
            name: cstr(b, stroff + sh(i, 0)? as usize),
            size: u64::from(sh(i, 20)?),
            alloc: flags & 2 != 0,
        });
        if ty == 2 {
            symtab = Some(i);
        }
    }
    let mut symbols = Vec::new();
    if let Some(s) = symtab {
        let off = sh(s, 16)? as usize;
        let size = sh(s, 20)? as usize;
        let strtab = sh(sh(s, 24)? as usize, 16)? as usize;
        for k in 0..size / 16 {
            let e = off + 16 * k;
            let st_size = u32le(b, e + 8).ok_or_else(bad)?;
            let shndx = u16le(b, e + 14).ok_or_else(bad)? as usize;
            if st_size == 0 || shndx == 0 || shndx >= sections.len() {
                continue;
            }
            symbols.push(Symbol {
                name: cstr(b, strtab + u32le(b, e).ok_or_else(bad)? as usize),
                size: u64::from(st_size),
                section: shndx,
            });
        }
    }
    Ok((sections, symbols))
}

/// The words of a (legacy-mangled) Rust symbol: path components and the type names of
/// `impl` blocks, lower case (`_ZN10faint_core6detect4crpf...` -> `faint_core`, `detect`,
/// `crpf`, ...).
pub fn words(sym: &str) -> Vec<String> {
    let mut out = Vec::new();
    let s = sym.strip_prefix("_ZN").unwrap_or(sym);
    let b = s.as_bytes();
    let mut i = 0;
    let mut any = false;
    while i < b.len() && b[i].is_ascii_digit() {
        let mut n = 0usize;
        while i < b.len() && b[i].is_ascii_digit() {
            n = n * 10 + usize::from(b[i] - b'0');
            i += 1;
        }
        let Some(id) = s.get(i..i + n) else {
            break;
        };
        any = true;
        for w in id.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')) {
            if !w.is_empty() {
                out.push(w.to_ascii_lowercase());
            }
        }
        i += n;
    }
    if !any {
        out.extend(
            sym.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .filter(|w| !w.is_empty())
                .map(|w| w.to_ascii_lowercase()),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_mangled_paths_and_impl_types() {
        let w = words("_ZN10faint_core6detect4crpf16CrpfTbd$LT$_$GT$4step17h0123456789abcdefE");
        assert!(w.contains(&"crpf".to_string()));
        assert!(w.contains(&"step".to_string()));
        let w = words("_ZN98_$LT$faint_core..detect..phd..SmcPhdTbd$LT$_$C$_$GT$$u20$as$u20$faint_core..detect..Detector$GT$4step17h0123456789abcdefE");
        assert!(w.contains(&"phd".to_string()));
        assert_eq!(words("memcpy"), vec!["memcpy".to_string()]);
    }

    #[test]
    fn rejects_non_elf_input() {
        assert!(read(b"not an elf").is_err());
    }
}
