"""The contract explain needs from a model is one Protocol, and both the library's model and the stand-in follow it."""
import pytest

from satmd.errors import SatmdError
from satmd.explain import ExplainableModel
from satmd.explain.contract import check_net_model


def test_inverse_model_and_stand_in_follow_the_contract(standin):
    from satmd.inverse import InverseModel

    # learned attributes (scaler_, networks_) exist once fitted; the methods are the class's
    assert all(callable(getattr(InverseModel, m, None)) for m in ("as_complex", "features", "latent"))
    assert isinstance(standin, ExplainableModel)
    check_net_model(standin)


def test_models_without_a_network_are_refused_in_one_line():
    from satmd.inverse import InverseModel

    for model in (InverseModel("optimization", "paper"), object()):
        with pytest.raises(SatmdError) as info:
            check_net_model(model)
        assert "\n" not in str(info.value)
