//! The Cortex-M4 budget's swarm (`PsoConfig::cortex_m4`): the paper's settings with at
//! most 128 particles moved per frame, and on the firmware's scene (the rows tagged
//! "swarm cap 128") the swarm moves exactly that many in every frame after the first.

use faint::detect::phd::{PsoConfig, SmcPhdTbdM4};
use faint::detect::Detector;
use faint::rng::Rng;
use faint_golden::phd::{config, cube, ALGORITHMS, FIRMWARE_WINDOW, FRAMES};

#[test]
fn cortex_m4_is_the_paper_with_a_swarm_of_128() {
    let m4 = PsoConfig::cortex_m4();
    assert_eq!(m4.max_members, 128);
    assert_eq!(
        PsoConfig {
            max_members: 512,
            ..m4
        },
        PsoConfig::paper()
    );
}

#[test]
fn cortex_m4_moves_128_particles_per_frame_on_the_firmware_scene() {
    const SEED: u64 = 0x0002_0019_9E1D_7BD0;
    for alg in ALGORITHMS.iter().filter(|a| a.pso) {
        let mut cfg = config(FIRMWARE_WINDOW, *alg, 1000, 500, 8);
        let points = cfg.pso.map_or(8, |p| p.points);
        cfg.pso = Some(PsoConfig {
            points,
            ..PsoConfig::cortex_m4()
        });
        let mut det = Box::new(SmcPhdTbdM4::new_unconfigured());
        det.configure(&cfg, SEED).unwrap();
        let mut rng = Rng::from_stream(SEED, 1);
        let mut buf = vec![0.0f32; FIRMWARE_WINDOW.len()];
        let mut swarm = Vec::new();
        for k in 0..FRAMES {
            cube(&FIRMWARE_WINDOW, k, &mut rng, &mut buf);
            swarm.push(det.step(&buf).unwrap().swarm);
        }
        assert_eq!(swarm[0], 0, "{}: {swarm:?}", alg.name);
        assert!(
            swarm[1..].iter().all(|&s| s == 128),
            "{}: {swarm:?}",
            alg.name
        );
    }
}
