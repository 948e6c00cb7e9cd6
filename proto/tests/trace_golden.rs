//! Golden bytes of the trace format (`docs/PROTOCOL.md` §10): a small trace written by the code, compared byte for
//! byte with bytes written by hand from the documented layout. The CRC-32 values were computed apart from this code,
//! with Python's `zlib.crc32` over the record contents below. A failure here means the trace format changed: either
//! the change is a bug, or it needs a new `trace::FORMAT` and an updated `docs/PROTOCOL.md`.

use cosim_proto::messages::StepCommand;
use cosim_proto::trace::{self, Kind, Node, RawEnvelope, Record, Torn};
use cosim_proto::Envelope;

/// Bytes from hex text; whitespace is ignored and `#` starts a comment that runs to the end of the line.
fn hex(text: &str) -> Vec<u8> {
    let digits: String = text
        .lines()
        .map(|line| line.split('#').next().unwrap_or(""))
        .flat_map(|line| line.chars().filter(|c| !c.is_whitespace()))
        .collect();
    (0..digits.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&digits[i..i + 2], 16).expect("hex digit"))
        .collect()
}

const GOLDEN: &str = "
    43 4f 53 49 4d 54 52 43                 # magic `COSIMTRC`
    01 00 00 00                             # format u32 = 1
    03 00 00 00                             # protocol_version u32 = 3
    # record 0: the scene
    16 00 00 00                             # len u32 = 22 = 10 + 12
    79 2f 86 33                             # crc32 = 33862f79
    01                                      # kind = 1 scene
    00                                      # node = 0 broker
    00 00 00 00 00 00 00 00                 # step u64 = 0
    76 65 72 73 69 6f 6e 20 3d 20 31 0a     # `version = 1\\n`
    # record 1: a command to fem-node
    3c 00 00 00                             # len u32 = 60 = 10 + 50
    27 2f 76 a3                             # crc32 = a3762f27
    04                                      # kind = 4 command
    01                                      # node = 1 fem-node
    03 00 00 00 00 00 00 00                 # step u64 = 3
    03 00 00 00                             #   envelope: protocol_version = 3
    02 00 00 00 00 00 00 00 72 31           #   run = \"r1\"
    03 00 00 00 00 00 00 00                 #   step = 3
    00 00 00 00 00 00 e0 3f                 #   t = 0.5
    00 00 00 00 00 00 d0 3f                 #   body: dt = 0.25
    00 00 00 00 00 00 00 00                 #   corrections: none
    00                                      #   roi: None
    01 00 00                                #   want_interface, want_snapshot, stop
    # record 2: the end
    0c 00 00 00                             # len u32 = 12 = 10 + 2
    5f 39 05 06                             # crc32 = 0605395f
    07                                      # kind = 7 end
    00                                      # node = 0 broker
    03 00 00 00 00 00 00 00                 # step u64 = 3
    7b 7d                                   # `{}`
";

fn command() -> Vec<u8> {
    let cmd = StepCommand {
        dt: 0.25,
        corrections: Vec::new(),
        roi: None,
        want_interface: true,
        want_snapshot: false,
        stop: false,
    };
    Envelope::new("r1", 3, 0.5, cmd).encode()
}

/// The golden trace, written by the code.
fn written() -> Vec<u8> {
    let mut out = trace::header(3).to_vec();
    out.extend(trace::encode(Kind::Scene, Node::Broker, 0, b"version = 1\n").unwrap());
    out.extend(trace::encode(Kind::Command, Node::Fem, 3, &command()).unwrap());
    out.extend(trace::encode(Kind::End, Node::Broker, 3, b"{}").unwrap());
    out
}

#[test]
fn trace_bytes_are_the_documented_layout() {
    assert_eq!(
        trace::FORMAT,
        1,
        "a new format needs new golden bytes and docs/PROTOCOL.md §10"
    );
    assert_eq!(written(), hex(GOLDEN));
}

#[test]
fn golden_trace_reads_back() {
    let t = trace::parse(&hex(GOLDEN)).unwrap();
    assert_eq!(t.protocol_version, 3);
    assert_eq!(t.torn, None);
    let kinds: Vec<_> = t.records.iter().map(|r| (r.kind, r.node, r.step)).collect();
    assert_eq!(
        kinds,
        [
            (Kind::Scene, Node::Broker, 0),
            (Kind::Command, Node::Fem, 3),
            (Kind::End, Node::Broker, 3)
        ]
    );
    assert_eq!(t.records[1].payload, command());
    let raw = RawEnvelope::split(&t.records[1].payload).unwrap();
    assert_eq!((raw.protocol_version, raw.run, raw.step, raw.t), (3, "r1", 3, 0.5));
    // Another run id: the header rebuilt, the body the same bytes.
    let moved = raw.for_run("replay-7");
    let back = Envelope::<StepCommand>::decode(&moved, "replay-7", "command").unwrap();
    assert_eq!(back.encode()[..], moved[..]);
    assert_eq!(RawEnvelope::split(&moved).unwrap().body, raw.body);
    // One node's part: the other records are read past, not kept.
    let fem = trace::parse_with(&hex(GOLDEN), |_, node| node == Node::Fem).unwrap();
    assert_eq!((fem.records.len(), fem.records[0].step, fem.torn), (1, 3, None));
    // Its place in the whole file (after the scene), not among the records kept.
    assert_eq!(fem.records[0].index, 1);
}

/// A file cut at any byte (a process killed mid-write) reads up to its last complete record and says where it stops.
#[test]
fn a_trace_cut_anywhere_reads_its_complete_records() {
    let full = hex(GOLDEN);
    let ends = [16, 16 + 8 + 22, 16 + 8 + 22 + 8 + 60, full.len()];
    for cut in 0..=full.len() {
        let read = trace::parse(&full[..cut]);
        if cut < 16 {
            assert_eq!(read, Err(trace::TraceError::NotATrace), "cut at {cut}");
            continue;
        }
        let t = read.unwrap();
        let complete = ends.iter().filter(|&&e| e <= cut).count() - 1;
        assert_eq!(t.records.len(), complete, "cut at {cut}");
        let last_end = ends[complete];
        match cut == last_end {
            true => assert_eq!(t.torn, None, "cut at {cut}"),
            false => assert_eq!(t.torn.as_ref().map(|t: &Torn| t.offset), Some(last_end), "cut at {cut}"),
        }
    }
}

/// One byte changed inside a record: reading stops there, on its checksum; an unknown format is refused.
#[test]
fn a_damaged_record_is_where_reading_stops() {
    let mut bytes = hex(GOLDEN);
    bytes[16 + 8 + 22 + 8 + 30] ^= 1;
    let t = trace::parse(&bytes).unwrap();
    assert_eq!(t.records.len(), 1);
    let torn = t.torn.unwrap();
    assert_eq!(torn.offset, 16 + 8 + 22);
    assert!(torn.why.contains("checksum"), "{}", torn.why);
    let mut other = hex(GOLDEN);
    other[8] = 2;
    assert_eq!(trace::parse(&other), Err(trace::TraceError::Format { got: 2 }));
    assert_eq!(
        trace::parse(b"not a trace at all").unwrap_err(),
        trace::TraceError::NotATrace
    );
    // A record is what it was written as.
    let r = Record {
        kind: Kind::State,
        node: Node::Sph,
        step: 9,
        payload: vec![1, 2, 3],
        index: 0,
    };
    let mut one = trace::header(2).to_vec();
    one.extend(trace::encode(r.kind, r.node, r.step, &r.payload).unwrap());
    assert_eq!(trace::parse(&one).unwrap().records, [r]);
}
