//! Round trip of one payload between two processes on this host over zenoh, with shared memory (zenoh's default
//! when it is compiled in, as here: a payload of 3 KB or more goes through a 16 MB shared-memory pool instead of the
//! socket) and without (`transport/shared_memory/enabled = false` on both sides). The sizes are those of a run:
//! a step command (1 KB), a fluid state of the gate at 1 mm (~44 KB, the particles in the region of interest),
//! 256 KB, a particle snapshot at an output step (~1 MB at 14,000 particles) and 4 MB.
//!
//! `cargo bench -p cosim-bus --bench payload` — the bench starts a copy of itself as the echoing peer.
//! `PAYLOAD_BENCH_REPS` (default 200) round trips per size after 20 warm-up ones; medians are printed.

use std::time::{Duration, Instant};

use zenoh::Wait;

const ECHO: &str = "PAYLOAD_BENCH_ECHO";
const SIZES: [usize; 5] = [1 << 10, 44 << 10, 256 << 10, 1 << 20, 4 << 20];

fn config(listen: Option<&str>, connect: Option<&str>, shm: bool) -> zenoh::Config {
    let mut c = zenoh::Config::default();
    let list = |e: Option<&str>| e.map_or("[]".to_string(), |e| format!("[{e:?}]"));
    for (k, v) in [
        ("mode", "\"peer\"".to_string()),
        ("scouting/multicast/enabled", "false".to_string()),
        ("listen/endpoints", list(listen)),
        ("connect/endpoints", list(connect)),
        ("transport/shared_memory/enabled", shm.to_string()),
    ] {
        c.insert_json5(k, &v).unwrap();
    }
    c
}

/// The child: answer every ping with the same bytes until the parent goes away.
fn echo(endpoint: &str, shm: bool) {
    let session = zenoh::open(config(None, Some(endpoint), shm)).wait().unwrap();
    let pings = session.declare_subscriber("bench/ping").wait().unwrap();
    let pong = session.declare_publisher("bench/pong").wait().unwrap();
    while let Ok(Some(sample)) = pings.recv_timeout(Duration::from_secs(20)) {
        pong.put(sample.payload().clone()).wait().unwrap();
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn measure(shm: bool, reps: usize) -> Vec<f64> {
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let session = zenoh::open(config(Some(&endpoint), None, shm)).wait().unwrap();
    let pongs = session.declare_subscriber("bench/pong").wait().unwrap();
    let ping = session.declare_publisher("bench/ping").wait().unwrap();
    let mut child = std::process::Command::new(std::env::current_exe().unwrap())
        .env(ECHO, format!("{endpoint},{shm}"))
        .spawn()
        .unwrap();
    // Ping until the peer answers: its subscription may take a moment to reach this session.
    let until = Instant::now() + Duration::from_secs(20);
    loop {
        ping.put(vec![0u8]).wait().unwrap();
        if pongs.recv_timeout(Duration::from_millis(200)).unwrap().is_some() {
            break;
        }
        assert!(Instant::now() < until, "the echo peer did not answer");
    }
    std::thread::sleep(Duration::from_millis(300));
    while let Ok(Some(_)) = pongs.try_recv() {}
    let mut medians = Vec::new();
    for size in SIZES {
        let payload: Vec<u8> = (0..size).map(|i| (i * 31 % 251) as u8).collect();
        let mut times = Vec::with_capacity(reps);
        for k in 0..reps + 20 {
            let started = Instant::now();
            ping.put(payload.clone()).wait().unwrap();
            let back = pongs.recv_timeout(Duration::from_secs(20)).unwrap().expect("pong");
            let took = started.elapsed().as_secs_f64();
            assert_eq!(back.payload().len(), size);
            if k >= 20 {
                times.push(took);
            }
        }
        medians.push(median(times));
    }
    drop(ping);
    let _ = child.kill();
    let _ = child.wait();
    medians
}

fn main() {
    if let Ok(arg) = std::env::var(ECHO) {
        let (endpoint, shm) = arg.split_once(',').unwrap();
        echo(endpoint, shm == "true");
        return;
    }
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let reps = std::env::var("PAYLOAD_BENCH_REPS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(200);
    let with = measure(true, reps);
    let without = measure(false, reps);
    println!("| payload | round trip, shared memory | round trip, TCP only | TCP / shared memory |");
    println!("|---:|---:|---:|---:|");
    for ((size, a), b) in SIZES.iter().zip(&with).zip(&without) {
        println!(
            "| {} KB | {:.3} ms | {:.3} ms | {:.2} |",
            size >> 10,
            a * 1e3,
            b * 1e3,
            b / a
        );
    }
}
