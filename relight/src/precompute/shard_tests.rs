use super::*;

/// A lookup of the variables `vars`.
fn env<'a>(vars: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
    move |name| {
        vars.iter()
            .find(|(k, _)| *k == name)
            .map(|(_, v)| v.to_string())
    }
}

fn shard_refusal(result: Result<Shard>) -> String {
    match result {
        Err(Error::Core(haarshift::Error::InvalidParameter {
            name: "shard",
            reason,
        })) => reason,
        other => panic!("expected a refused shard, got {other:?}"),
    }
}

#[test]
fn the_ranges_cover_every_vertex_once_in_order() {
    for total in [0, 1, 2, 7, 10, 1143, 85_860] {
        for count in [1, 2, 3, 7, 8, 64, 1000] {
            let mut next = 0;
            for index in 0..count {
                let r = Shard::new(index, count).unwrap().range(total);
                assert_eq!(r.start, next, "{index}/{count} of {total}");
                assert!(r.len() == total / count || r.len() == total / count + 1);
                next = r.end;
            }
            assert_eq!(next, total);
        }
    }
    // Near the largest counts the products would overflow u64.
    let huge = Shard::new(usize::MAX - 1, usize::MAX).unwrap();
    assert_eq!(huge.range(usize::MAX), usize::MAX - 1..usize::MAX);
}

#[test]
fn shards_parse_and_print_as_i_of_n() {
    assert_eq!("0/1".parse::<Shard>().unwrap(), Shard::whole());
    assert_eq!(Shard::new(6, 7).unwrap().to_string(), "6/7");
    for bad in ["", "3", "3/", "/3", "-1/3", "a/b", "1/0", "3/3", "1/2/3"] {
        let needle = if bad.ends_with("/0") || bad == "3/3" {
            "the index must be below the count"
        } else {
            "expected I/N (shard I of N, counting from 0) or auto"
        };
        assert_err!(
            bad.parse::<Shard>(),
            InvalidParameter { name: "shard", .. },
            needle
        );
    }
    assert_eq!(
        "2/2".parse::<ShardSpec>().unwrap_err().to_string(),
        "invalid shard: 2/2: the index must be below the count (0 to 2 - 1)"
    );
}

#[test]
fn a_slurm_array_names_its_task() {
    let base = [
        ("SLURM_ARRAY_TASK_MIN", "0"),
        ("SLURM_ARRAY_TASK_MAX", "6"),
        ("SLURM_ARRAY_TASK_COUNT", "7"),
    ];
    for id in 0..7 {
        let id_text = id.to_string();
        let mut vars = base.to_vec();
        vars.push(("SLURM_ARRAY_TASK_ID", &id_text));
        let shard = Shard::from_env(env(&vars), None).unwrap();
        assert_eq!(shard, Shard::new(id, 7).unwrap());
        // Kubernetes' variable is ignored under Slurm.
        vars.push(("JOB_COMPLETION_INDEX", "3"));
        assert_eq!(Shard::from_env(env(&vars), Some(7)).unwrap(), shard);
    }
    // --array=10-30:5: tasks 10, 15, 20, 25, 30 are shards 0 to 4.
    let stepped = [
        ("SLURM_ARRAY_TASK_ID", "25"),
        ("SLURM_ARRAY_TASK_MIN", "10"),
        ("SLURM_ARRAY_TASK_MAX", "30"),
        ("SLURM_ARRAY_TASK_STEP", "5"),
        ("SLURM_ARRAY_TASK_COUNT", "5"),
    ];
    assert_eq!(
        Shard::from_env(env(&stepped), None).unwrap(),
        Shard::new(3, 5).unwrap()
    );
    assert_eq!(
        Shard::from_env(env(&stepped), None).unwrap().range(1000),
        600..800
    );
}

#[test]
fn a_slurm_array_with_gaps_or_a_wrong_count_is_refused() {
    // --array=0,2,5: min 0, max 5, step 1, but 3 tasks.
    let gaps = [
        ("SLURM_ARRAY_TASK_ID", "2"),
        ("SLURM_ARRAY_TASK_MIN", "0"),
        ("SLURM_ARRAY_TASK_MAX", "5"),
        ("SLURM_ARRAY_TASK_STEP", "1"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ];
    assert!(shard_refusal(Shard::from_env(env(&gaps), None)).contains("has gaps"));
    // A task off the step.
    let off = [
        ("SLURM_ARRAY_TASK_ID", "3"),
        ("SLURM_ARRAY_TASK_MIN", "0"),
        ("SLURM_ARRAY_TASK_MAX", "4"),
        ("SLURM_ARRAY_TASK_STEP", "2"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ];
    assert!(shard_refusal(Shard::from_env(env(&off), None)).contains("has gaps"));
    let ok = [
        ("SLURM_ARRAY_TASK_ID", "1"),
        ("SLURM_ARRAY_TASK_MIN", "0"),
        ("SLURM_ARRAY_TASK_COUNT", "4"),
    ];
    assert_eq!(
        shard_refusal(Shard::from_env(env(&ok), Some(3))),
        "auto: --shards 3 but the Slurm array has 4 tasks"
    );
    assert_eq!(
        Shard::from_env(env(&ok), Some(4)).unwrap(),
        Shard::new(1, 4).unwrap()
    );
    let no_count = [("SLURM_ARRAY_TASK_ID", "1"), ("SLURM_ARRAY_TASK_MIN", "0")];
    assert!(
        shard_refusal(Shard::from_env(env(&no_count), None)).contains("SLURM_ARRAY_TASK_COUNT")
    );
    let junk = [("SLURM_ARRAY_TASK_ID", "x")];
    assert!(shard_refusal(Shard::from_env(env(&junk), None)).contains("SLURM_ARRAY_TASK_ID=\"x\""));
}

#[test]
fn a_kubernetes_indexed_job_needs_its_count() {
    let k8s = [("JOB_COMPLETION_INDEX", "5")];
    assert_eq!(
        Shard::from_env(env(&k8s), Some(6)).unwrap().range(60),
        50..60
    );
    assert!(shard_refusal(Shard::from_env(env(&k8s), None)).contains("--shards N"));
    assert!(shard_refusal(Shard::from_env(env(&k8s), Some(5))).contains("below the count"));
}

#[test]
fn no_scheduler_is_refused_in_one_line() {
    let reason = shard_refusal(ShardSpec::Auto.resolve(env(&[]), Some(4)));
    assert!(reason.contains("neither SLURM_ARRAY_TASK_ID"));
    assert!(!reason.contains('\n'));
    let given = ShardSpec::Given(Shard::new(0, 2).unwrap());
    assert!(shard_refusal(given.resolve(env(&[]), Some(2))).contains("--shards goes with"));
}
