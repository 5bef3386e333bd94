pub struct Fig5Options {
    pub snr: f32,
    pub noise_tracks: usize,
    pub target_tracks: usize,
    pub frames: usize,
    pub pfa: f64,
    pub seed: u64,
}
pub fn run(opts: &Fig5Options, out: &std::path::Path) -> anyhow::Result<String> {
    anyhow::bail!("Fig. 5 analysis not built")
}
