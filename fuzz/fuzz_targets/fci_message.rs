//! Arbitrary bytes from a Franka controller: as a state datagram (raw, and
//! cut or padded to a state's size), as a command datagram, and as a TCP
//! stream of command-channel messages. Each gives a message or an error,
//! never a panic; a state that decodes has finite joints and encodes to
//! bytes that decode and encode to themselves; a command that decodes encodes to bytes
//! that decode and encode to themselves; the stream reader only ever returns whole messages and leaves the
//! rest.
#![no_main]

use libfuzzer_sys::fuzz_target;
use primo_franka::wire::{
    COMMAND_SIZE, Message, MoveRequest, RobotCommand, RobotState, STATE_SIZE,
};

fuzz_target!(|data: &[u8]| {
    let mut sized = data.to_vec();
    sized.resize(STATE_SIZE, 0);
    for bytes in [data, &sized[..]] {
        if let Ok(s) = RobotState::decode(bytes) {
            assert!(
                s.q.iter()
                    .chain(&s.q_d)
                    .chain(&s.dq)
                    .chain(&s.dq_d)
                    .all(|v| v.is_finite())
            );
            // Compared as bytes: a torque may be NaN (it is not used).
            let once = s.encode();
            let twice = RobotState::decode(&once).map(|s| s.encode());
            assert_eq!(twice.map(|b| b.to_vec()), Ok(once.to_vec()));
        }
    }
    let mut command = data.to_vec();
    command.resize(COMMAND_SIZE, 0);
    if let Ok(c) = RobotCommand::decode(&command) {
        // What primo reads of a command it writes back the same (the
        // fields it does not model are written as zeros).
        let once = c.encode();
        let twice = RobotCommand::decode(&once).map(|c| c.encode());
        assert_eq!(twice, Ok(once));
    }
    let _ = MoveRequest::decode(data);
    let mut stream = data.to_vec();
    let before = stream.len();
    while let Ok(Some(m)) = Message::take(&mut stream) {
        let _ = m.status();
    }
    assert!(stream.len() <= before);
});
