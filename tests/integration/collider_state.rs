//! The `/colliders/state` channel read back with the `mcap` crate: a `jsonschema` schema, one
//! JSON message per logged frame, every collider at the pose its motion prescribes.

use crate::common;

use common::*;

fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .expect("an array")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

#[test]
fn every_frame_lists_every_collider_at_its_analytic_pose() {
    let dir = temp_dir("collider-state");
    let log = logged_run(&dir, "moving.toml", MOVING, 30, "m.mcap");
    let bytes = std::fs::read(&log).expect("log");
    let summary = mcap::Summary::read(&bytes)
        .expect("summary")
        .expect("a summary");
    let channel = summary
        .channels
        .values()
        .find(|c| c.topic == "/colliders/state")
        .expect("the channel");
    assert_eq!(channel.message_encoding, "json");
    let schema = channel.schema.as_ref().expect("a schema");
    assert_eq!(schema.encoding, "jsonschema");
    let schema: serde_json::Value = serde_json::from_slice(&schema.data).expect("JSON");
    assert_eq!(schema["$schema"], "http://json-schema.org/draft-07/schema#");
    let mut frames = Vec::new();
    let mut stats_frames = Vec::new();
    for m in mcap::MessageStream::new(&bytes).expect("readable") {
        let m = m.expect("a message");
        let v: serde_json::Value = match m.channel.topic.as_str() {
            "/colliders/state" | "/stats" => serde_json::from_slice(&m.data).expect("JSON"),
            _ => continue,
        };
        if m.channel.topic == "/stats" {
            stats_frames.push(v["frame"].as_u64().expect("frame"));
            continue;
        }
        let t = m.log_time as f64 * 1e-9;
        assert!((v["time"].as_f64().expect("time") - t).abs() < 1e-9);
        frames.push(v["frame"].as_u64().expect("frame"));
        let cs = v["colliders"].as_array().expect("colliders");
        let names: Vec<&str> = cs
            .iter()
            .map(|c| c["name"].as_str().expect("name"))
            .collect();
        assert_eq!(names, ["ball", "rod", "box", "ground"]);
        let close = |got: &serde_json::Value, want: [f64; 3]| {
            let got = numbers(got);
            let err = (0..3).map(|i| (got[i] - want[i]).abs()).fold(0.0, f64::max);
            assert!(err < 1e-9, "frame {}: {got:?} vs {want:?}", v["frame"]);
        };
        // x0 + v t.
        close(&cs[0]["position"], [0.3 * t, 0.5, -0.1 * t]);
        assert_eq!(cs[0]["shape"], "sphere");
        assert_eq!(cs[0]["radius"], 0.2);
        // x0 + A sin(2π f t).
        let s = (2.0 * std::f64::consts::PI * 2.0 * t).sin();
        close(&cs[1]["position"], [1.0, 0.2 + 0.1 * s, 0.0]);
        assert_eq!(cs[1]["shape"], "capsule");
        assert_eq!(
            (&cs[1]["radius"], &cs[1]["half_height"]),
            (&0.05.into(), &0.3.into())
        );
        close(&cs[2]["position"], [-1.0, 0.3, 0.0]);
        assert_eq!(numbers(&cs[2]["half_extents"]), [0.1, 0.2, 0.3]);
        assert_eq!(numbers(&cs[2]["rotation"]), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(cs[3]["shape"], "plane");
        close(&cs[3]["normal"], [0.0, 1.0, 0.0]);
        assert_eq!(cs[3]["offset"], -0.5);
    }
    assert_eq!(
        frames,
        (0..=30).collect::<Vec<u64>>(),
        "one message per frame"
    );
    assert_eq!(frames, stats_frames);
}

#[test]
fn a_scene_without_colliders_has_no_state_channel() {
    let dir = temp_dir("collider-state-none");
    let scene = write(&dir, "small.toml", SMALL);
    let log = dir.join("s.mcap");
    let out = run(&[
        "run",
        &scene,
        "--frames",
        "3",
        "--out",
        &log.to_string_lossy(),
    ]);
    assert!(out.status.success(), "{:?}", texts(&out));
    let log = read_log(&log);
    assert!(
        !log.counts.contains_key("/colliders/state"),
        "{:?}",
        log.counts
    );
    assert_eq!(log.counts["/stats"], 4);
}
