"""bench_link's verdicts on issue 27's targets for the deployed path: held up to each bound."""
from bench import bench_link


def summary(added_p99: float, lost: int, remote: float, operator: float) -> dict:
    """The parts of ``bench_link.summarize``'s result that the verdicts read."""
    return {'in_process': {'added_ms': {'p99': added_p99}, 'lost': lost, 'sent': 120000},
            'in_process_gateway_cpu_pct': {'in_process': remote},
            'operator_in_process_gateway_cpu_pct': {'in_process': operator}}


def test_each_target_holds_up_to_its_bound_and_is_missed_past_it():
    at_bounds = bench_link.verdicts(summary(2.0, 0, 10.0, 10.0))
    assert [holds for _, holds in at_bounds] == [True, True, True, True]
    past = bench_link.verdicts(summary(2.01, 1, 10.1, 9.9))
    assert [holds for _, holds in past] == [False, False, False, True]


def test_each_verdict_says_what_was_measured_and_against_what():
    texts = [what for what, _ in bench_link.verdicts(summary(1.872, 0, 13.7, 15.4))]
    assert texts == ['round trip p99 +1.87 ms over the floor (target <= +2 ms)',
                     '0 of 120000 lost (target none)',
                     'the remote gateway 13.7 % of a core (target <= 10 %)',
                     'the operator gateway 15.4 % of a core (target <= 10 %)']
