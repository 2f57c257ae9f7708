//! Hardware in the loop: the firmware on an emulated Cortex-M4F (QEMU
//! mps2-an386), reached through a pseudo-terminal like a USB-serial adapter.

use primo_core::golden::SearchConfig;
use primo_core::generalize::Method;
use primo_core::service::Coprocessor as Service;
use primo_core::wire::{LearnerSetup, Outcome, Reply, Request, Setup};
use primo_host::coprocessor::{Link, Qemu};

#[test]
fn golden_section_on_the_mcu_matches_the_host() {
    let qemu = Qemu::start(&Qemu::default_firmware()).unwrap();
    let mut link = Link::open(qemu.pty()).unwrap();
    let mut local = Service::new();
    let cfg = SearchConfig { low: 0.1, high: 1.5, desired: 0.5, precision: 1e-4, max_rollouts: 40 };
    let setup = Request::Configure(Setup {
        learner: LearnerSetup::Golden(cfg),
        examples: 0,
        theta_len: 0,
        regression: Method::Lwr { bandwidth: None },
        seed: 1,
    });
    assert_eq!(link.call(&setup).unwrap(), local.respond(&setup));
    loop {
        let (a, b) = (link.call(&Request::Ask).unwrap(), local.respond(&Request::Ask));
        assert_eq!(a, b);
        let Reply::Rollout(r) = a else { break };
        let tell = Request::Tell(Outcome { error: 0.7 - r.query, reward: 0.0 });
        assert_eq!(link.call(&tell).unwrap(), local.respond(&tell));
    }
    println!("{:?}", link.stats());
}
